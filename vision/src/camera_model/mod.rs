//! Standard camera models of omnidirectional cameras, fitted to known rays and written in the
//! calibration tools' own files: Mei's unified model for OpenCV's `omnidir` module and Kalibr's
//! `omni` camera.

pub mod files;
pub mod fit;
pub mod unified;

pub use files::{ModelPose, kalibr_omni_yaml, opencv_omnidir_yaml};
pub use fit::{Correspondence, FitResidual, fit_unified, residual};
pub use unified::UnifiedModel;
