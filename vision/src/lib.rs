//! omniloop-vision: image processing and estimation for omnidirectional images of a floor.
//!
//! Everything here takes images (`image::RgbaImage`) and a calibration of the image-to-floor
//! map, never a simulated world, so it works the same on a real camera's PNG.

pub mod ball;
pub mod calibration;
pub mod camera_model;
pub mod floor_localization;
pub mod forward;
pub mod freespace;
pub mod geometry;
pub mod goal;
pub mod image_centre;
pub mod luminance_heading;
pub mod mask;
pub mod omnistereo;
pub mod pixels;
pub mod resection;

pub use ball::{BallColor, BallConfig, BallMiss, BallSighting};
pub use calibration::{HyperbolicFit, RadialCalibration};
pub use floor_localization::{
    ColorClass, FieldModel, FloorLocalizer, Localization, LocalizationConfig, LocalizationMethod,
    LocalizationMode, LocalizationQuality, PoseEstimate,
};
pub use freespace::{FloorPixels, FreeSpace, FreeSpaceConfig, FreeSpaceDetector, FreeSpaceMethod};
pub use mask::{FloorColor, Mask};

/// Errors of the vision crate.
#[derive(Debug, thiserror::Error)]
pub enum VisionError {
    /// A calibration that cannot be used.
    #[error("calibration: {0}")]
    Calibration(String),
    /// A calibration file that cannot be read or parsed.
    #[error("calibration file {path}: {message}")]
    CalibrationFile {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// A camera model file that cannot be read or parsed.
    #[error("calibration file {path}: {error}")]
    CameraFile {
        /// The file.
        path: String,
        /// What is wrong, and where in it.
        error: Box<camera_model::CameraFileError>,
    },
    /// A parameter outside its range.
    #[error("{name} = {value}: {rule}")]
    InvalidParameter {
        /// Name with unit.
        name: &'static str,
        /// Value.
        value: f64,
        /// The rule it breaks.
        rule: &'static str,
    },
    /// A profile whose contrast is too low to read marks in.
    #[error("not found: contrast {contrast:.0} grey levels, need {needed:.0}")]
    LowContrast {
        /// Its contrast: brightest minus darkest, grey levels.
        contrast: f64,
        /// The contrast needed, grey levels.
        needed: f64,
    },
    /// The image does not show what the method looks for (a degenerate or empty image).
    #[error("not found: {0}")]
    NotFound(String),
}

/// `value` must be a positive finite number.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<(), VisionError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(VisionError::InvalidParameter {
            name,
            value,
            rule: "must be positive",
        })
    }
}
