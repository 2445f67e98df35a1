//! Standard camera models of omnidirectional cameras, fitted to known rays and written in the
//! calibration tools' own files: Mei's unified model for OpenCV's `omnidir` module and Kalibr's
//! `omni` camera, the double sphere model for Kalibr's `ds` camera, Scaramuzza's polynomial
//! for the OCamCalib toolbox.

pub mod double_sphere;
pub mod files;
pub mod fit;
pub mod ocamcalib;
pub mod read;
pub mod unified;

pub use double_sphere::{DoubleSphereModel, fit_double_sphere};
pub use files::{ModelPose, kalibr_ds_yaml, kalibr_omni_yaml, opencv_omnidir_yaml};
pub use fit::{Correspondence, FitResidual, Projection, fit_unified, refine, residual};
pub use ocamcalib::{OcamModel, PolynomialError};
pub use read::{
    CameraFile, CameraFileError, FORMATS, FieldProblem, parse_camera_file, read_camera_file,
};
pub use unified::UnifiedModel;
