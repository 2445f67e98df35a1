//! A camera known only by its calibration file (`[robot.sensors.calibrated]`): an OpenCV
//! `omnidir` or Kalibr `omni` file (Mei's unified model), a Kalibr `ds` file (the double
//! sphere model) or an OCamCalib `calib_results.txt` (Scaramuzza's polynomial), with where the
//! model's frame sits on the robot.
//!
//! Each pixel's ray is the model's own unprojection (see
//! [`omniloop_vision::camera_model::CameraFile::unproject`]), turned into the robot frame by
//! the model frame's rotation and leaving from its single viewpoint, the frame's origin:
//! `o = t`, `d = R d_model`, with `R`'s columns the model's axes in the robot frame. Pixels the
//! model has no ray for, and pixels beyond `image_circle_px` from the principal point (the
//! mirror's rim in the image), are black.
//!
//! The image coordinates of [`super::Optics::scene_ray`] (`X` right, `Y` up from the sensor's
//! principal point, pixel edges at integers) become the model's pixel (centres at integers) as
//! `u = c_u + X`, `v = c_v - Y`, the sensor's principal point being the model's plus half a
//! pixel ([`CalibratedCamera::principal_point_px`]).

use super::ray::Ray;
use nalgebra::{Matrix3, Point3};
use omniloop_problem::{Problem, Problems};
use omniloop_vision::VisionError;
use omniloop_vision::camera_model::{CameraFile, FORMATS, read_camera_file};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A calibrated camera as the scenario describes it, with its model once read.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibratedCamera {
    /// The calibration file (in a scenario: relative to the scenario's file).
    pub file: PathBuf,
    /// Its format: `opencv-omnidir`, `ocamcalib`, `kalibr-omni` or `kalibr-ds`.
    pub format: String,
    /// The model frame's axes in the robot frame (the matrix's columns; rows as written).
    /// Default: the frame `omniloop calibrate` writes for the format, a camera on the robot's
    /// vertical axis with image x along the robot's forward axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<[[f64; 3]; 3]>,
    /// The model frame's origin (its single viewpoint) in the robot frame: x forward, y left,
    /// z up from the floor.
    pub translation_mm: [f64; 3],
    /// Radius about the principal point beyond which pixels are black (the mirror's rim in
    /// the image). Default: every pixel the model has a ray for.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image_circle_px: Option<f64>,
    /// The model, once [`CalibratedCamera::load`] has read the file.
    #[serde(skip)]
    model: Model,
}

/// Whether the file has been read, and what it gave.
#[derive(Debug, Clone, Default, PartialEq)]
enum Model {
    /// Not yet.
    #[default]
    Unread,
    /// Its model.
    Read(Arc<CameraFile>),
    /// Why it could not be read.
    Failed(String),
}

/// The unified and double sphere models' frame in the robot frame, as `omniloop calibrate`
/// writes it: x forward, y right, z down (columns).
pub const UNIFIED_FRAME: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]];

/// OCamCalib's frame in the robot frame, as `omniloop calibrate` writes it: x along the image
/// rows (the robot's right), y along the columns (forward), z up (columns).
pub const OCAM_FRAME: [[f64; 3]; 3] = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];

impl CalibratedCamera {
    /// A calibrated camera read from `file` now (no scenario involved).
    pub fn from_file(
        file: &Path,
        format: &str,
        rotation: Option<[[f64; 3]; 3]>,
        translation_mm: [f64; 3],
        image_circle_px: Option<f64>,
    ) -> Result<Self, VisionError> {
        let mut c = Self {
            file: file.to_path_buf(),
            format: format.to_string(),
            rotation,
            translation_mm,
            image_circle_px,
            model: Model::Unread,
        };
        c.load(Path::new(""))?;
        Ok(c)
    }

    /// Reads the file, relative to `base` where it is relative. A failure is kept too, and
    /// [`CalibratedCamera::problems`] reports it.
    pub fn load(&mut self, base: &Path) -> Result<(), VisionError> {
        if self.file.is_relative() {
            self.file = base.join(&self.file);
        }
        match read_camera_file(&self.file, &self.format) {
            Ok(m) => {
                self.model = Model::Read(Arc::new(m));
                Ok(())
            }
            Err(e) => {
                self.model = Model::Failed(e.to_string());
                Err(e)
            }
        }
    }

    /// The model, once read.
    pub fn model(&self) -> Option<&CameraFile> {
        match &self.model {
            Model::Read(m) => Some(m),
            _ => None,
        }
    }

    /// The rotation, the given one or the format's default.
    pub fn rotation_matrix(&self) -> Matrix3<f64> {
        let rows = self.rotation.unwrap_or(match self.format.as_str() {
            "ocamcalib" => OCAM_FRAME,
            _ => UNIFIED_FRAME,
        });
        Matrix3::from_fn(|i, j| rows[i][j])
    }

    /// The sensor's principal point (pixel edges at integers): the model's plus half a pixel.
    pub fn principal_point_px(&self) -> Option<[f64; 2]> {
        self.model().map(|m| m.principal_px().map(|c| c + 0.5))
    }

    /// The scene ray of image coordinates `(X, Y)` (see the module's doc).
    pub fn scene_ray(&self, x_px: f64, y_px: f64) -> Option<Ray> {
        let model = self.model()?;
        if self.image_circle_px.is_some_and(|r| x_px.hypot(y_px) > r) {
            return None;
        }
        let [cu, cv] = model.principal_px();
        let d = model.unproject([cu + x_px, cv - y_px])?;
        let [tx, ty, tz] = self.translation_mm;
        Some(Ray {
            origin: Point3::new(tx, ty, tz),
            dir: self.rotation_matrix() * d,
            path_mm: 0.0,
        })
    }

    /// Its numbers that break a rule: the key and why.
    pub fn problems(&self) -> Vec<Problem> {
        let mut p = Problems::new();
        if !FORMATS.contains(&self.format.as_str()) {
            p.fail(
                "format",
                format!(
                    "{:?} is not a camera model format (one of: {})",
                    self.format,
                    FORMATS.join(", ")
                ),
            );
        } else if let Model::Failed(why) = &self.model {
            p.fail("file", why.clone());
        } else if self.model == Model::Unread {
            p.fail("file", "the calibration file has not been read");
        }
        if let Some(CameraFile::Ocam(m)) = self.model()
            && m.pol.len() > MAX_POLYNOMIAL
        {
            p.fail(
                "file",
                format!(
                    "{}: OCamCalib polynomials up to degree {} are traced (this one has degree \
                     {})",
                    self.file.display(),
                    MAX_POLYNOMIAL - 1,
                    m.pol.len() - 1
                ),
            );
        }
        if self.translation_mm.iter().any(|v| !v.is_finite()) {
            p.fail("translation_mm", "must be finite numbers");
        }
        if let Some(r) = self.image_circle_px {
            p.positive("image_circle_px", r);
        }
        let r = self.rotation_matrix();
        let off = (r.transpose() * r - Matrix3::identity()).abs().max();
        if !(off < 1e-6 && (r.determinant() - 1.0).abs() < 1e-6) {
            p.fail(
                "rotation",
                "must be a rotation (orthonormal rows, determinant 1)",
            );
        }
        p.into_vec()
    }

    /// How far the viewpoint is from the sensor's axis, horizontally.
    pub fn max_origin_offset_mm(&self) -> f64 {
        self.translation_mm[0].hypot(self.translation_mm[1])
    }
}

/// Most coefficients of an OCamCalib polynomial the tracers take (degree 8).
pub const MAX_POLYNOMIAL: usize = 9;

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use omniloop_vision::camera_model::{ModelPose, UnifiedModel, opencv_omnidir_yaml};

    fn camera(dir: &Path) -> CalibratedCamera {
        let m = UnifiedModel {
            focal_px: [110.0, 110.0],
            skew_px: 0.0,
            principal_px: [127.5, 109.5],
            xi: 0.97,
            distortion: [0.0; 4],
        };
        let pose = ModelPose {
            rotation: Matrix3::from_fn(|i, j| UNIFIED_FRAME[i][j]),
            translation_mm: Vector3::new(0.0, 0.0, 205.0),
        };
        let file = dir.join("omni.yaml");
        std::fs::write(&file, opencv_omnidir_yaml(&m, [256, 220], &pose, "")).unwrap();
        CalibratedCamera::from_file(&file, "opencv-omnidir", None, [0.0, 0.0, 205.0], None).unwrap()
    }

    #[test]
    fn the_principal_ray_leaves_the_viewpoint_along_the_model_axis() {
        let dir = std::env::temp_dir().join(format!("omniloop-calibrated-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let c = camera(&dir);
        assert!(c.problems().is_empty(), "{:?}", c.problems());
        assert_eq!(c.principal_point_px(), Some([128.0, 110.0]));
        // The principal ray: the model's z, which is the robot's -z.
        let ray = c.scene_ray(0.0, 0.0).unwrap();
        assert_eq!(ray.origin, Point3::new(0.0, 0.0, 205.0));
        assert!((ray.dir - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-12);
        // Image x is the robot's forward axis, image Y (up) its left.
        let ahead = c.scene_ray(50.0, 0.0).unwrap().dir;
        let left = c.scene_ray(0.0, 50.0).unwrap().dir;
        assert!(ahead.x > 0.0 && ahead.y.abs() < 1e-12, "{ahead}");
        assert!(left.y > 0.0 && left.x.abs() < 1e-12, "{left}");
        // The image circle blacks out the rim.
        let circled = CalibratedCamera {
            image_circle_px: Some(40.0),
            ..c.clone()
        };
        assert!(circled.scene_ray(30.0, 0.0).is_some());
        assert!(circled.scene_ray(30.0, 30.0).is_none());
        // A rotation that is not one.
        let bent = CalibratedCamera {
            rotation: Some([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]]),
            ..c
        };
        assert_eq!(bent.problems()[0].field.to_string(), "rotation");
        std::fs::remove_dir_all(&dir).ok();
    }
}
