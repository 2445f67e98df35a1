//! A mirror sensor as a standard camera model: Mei's unified model fitted to the sensor's
//! traced rays (every pixel that sees the mirror), written for OpenCV's `omnidir` module or as
//! a Kalibr `omni` camera, with where the model's frame sits on the robot.
//!
//! The model's frame: its origin is the point nearest to all the sensor's rays (the upper focus
//! of a hyperbolic mirror, where they all meet); x is the robot's forward axis, y points to the
//! robot's right and z down, so that image x grows with the robot's x and image v (down) with
//! its -y, as in omniloop's images. For a non-central mirror (conical, spherical) the rays miss
//! that point by up to the reported viewpoint spread, and the fit's residual says how far the
//! single-viewpoint model is from the real camera.

use nalgebra::{Matrix3, Vector3};
use omniloop_sim::optics::Optics;
use omniloop_sim::{Sensor, SensorSpec};
use omniloop_vision::VisionError;
use omniloop_vision::camera_model::{
    CameraFile, Correspondence, DoubleSphereModel, FitResidual, ModelPose, OcamModel, UnifiedModel,
    fit_double_sphere, fit_unified, kalibr_ds_yaml, kalibr_omni_yaml, opencv_omnidir_yaml,
    parse_camera_file, residual as reprojection,
};

/// A camera model file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraFormat {
    /// OpenCV `omnidir` (Mei's unified model: `K`, `xi`, `D`), a `cv::FileStorage` YAML.
    OpencvOmnidir,
    /// Kalibr's camchain YAML with `camera_model: omni`, `distortion_model: radtan`.
    KalibrOmni,
    /// Kalibr's camchain YAML with `camera_model: ds` (the double sphere model).
    KalibrDs,
    /// OCamCalib's `calib_results.txt` (Scaramuzza's polynomial).
    Ocamcalib,
}

/// A fitted model: which, and its intrinsics.
#[derive(Debug, Clone, PartialEq)]
pub enum FittedModel {
    /// Mei's unified model (OpenCV `omnidir`, Kalibr `omni`).
    Unified(UnifiedModel),
    /// The double sphere model (Kalibr `ds`).
    DoubleSphere(DoubleSphereModel),
    /// Scaramuzza's polynomial (OCamCalib).
    Ocam(OcamModel),
}

impl FittedModel {
    /// Its intrinsics as JSON.
    fn json(&self) -> serde_json::Value {
        match self {
            FittedModel::Unified(m) => serde_json::json!({
                "model": "unified (Mei)",
                "focal_px": m.focal_px,
                "skew_px": m.skew_px,
                "principal_point_px": m.principal_px,
                "xi": m.xi,
                "distortion_k1_k2_p1_p2": m.distortion,
            }),
            FittedModel::DoubleSphere(m) => serde_json::json!({
                "model": "double sphere",
                "focal_px": m.focal_px,
                "principal_point_px": m.principal_px,
                "xi": m.xi,
                "alpha": m.alpha,
            }),
            FittedModel::Ocam(m) => serde_json::json!({
                "model": "OCamCalib polynomial (Scaramuzza)",
                "pol": m.pol,
                "invpol": m.invpol,
                "center_row_col_px": m.center_rc,
                "affine_c_d_e": m.affine,
            }),
        }
    }

    /// A line of its main figures.
    pub fn summary(&self) -> String {
        match self {
            FittedModel::Unified(m) => format!(
                "xi {:.5}, f {:.3} / {:.3} px",
                m.xi, m.focal_px[0], m.focal_px[1]
            ),
            FittedModel::DoubleSphere(m) => format!(
                "xi {:.5}, alpha {:.5}, f {:.3} / {:.3} px",
                m.xi, m.alpha, m.focal_px[0], m.focal_px[1]
            ),
            FittedModel::Ocam(m) => format!(
                "f(rho) of degree {}, inverse of degree {}",
                m.pol.len() - 1,
                m.invpol.len() - 1
            ),
        }
    }
}

impl CameraFormat {
    /// Every format, by the name the command line takes.
    pub const ALL: [(&'static str, CameraFormat); 4] = [
        ("opencv-omnidir", CameraFormat::OpencvOmnidir),
        ("ocamcalib", CameraFormat::Ocamcalib),
        ("kalibr-omni", CameraFormat::KalibrOmni),
        ("kalibr-ds", CameraFormat::KalibrDs),
    ];

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, f)| *f == self)
            .map_or("?", |(n, _)| n)
    }
}

/// Why a sensor cannot be exported.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The sensor has no mirror.
    #[error("sensor {0:?} is a pinhole camera: the omnidirectional models are for mirror sensors")]
    NotAMirror(String),
    /// The fit failed.
    #[error("sensor {sensor:?}: {reason}")]
    Fit {
        /// The sensor.
        sensor: String,
        /// What failed.
        reason: omniloop_vision::VisionError,
    },
}

/// A fitted model, its file's text and the figures of the fit.
#[derive(Debug, Clone)]
pub struct CameraExport {
    /// The fitted model.
    pub model: FittedModel,
    /// The model's frame on the robot.
    pub pose: ModelPose,
    /// Reprojection residual over every traced ray.
    pub residual: FitResidual,
    /// Largest distance (mm) of a ray from the model's viewpoint (0 for a central mirror).
    pub viewpoint_spread_mm: f64,
    /// Radius about the principal point beyond which the mirror is not seen (`None`: it
    /// fills the image to its corners); `image_circle_px` of a `calibrated` sensor.
    pub image_circle_px: Option<f64>,
    /// The file, in the format asked for.
    pub text: String,
    /// The same as JSON: model, pose and residual (written beside the file).
    pub json: serde_json::Value,
}

/// Fits the unified model to `spec`'s traced rays and writes it as `format`.
pub fn export_camera_model(
    spec: &SensorSpec,
    format: CameraFormat,
) -> Result<CameraExport, ExportError> {
    if matches!(spec.optics, Optics::Pinhole(_)) {
        return Err(ExportError::NotAMirror(spec.name.clone()));
    }
    let sensor = spec.build();
    let (rays, dark_radii) = traced_rays(&sensor);
    let image_circle_px = image_circle(&sensor, &rays, &dark_radii);
    let viewpoint = nearest_point(&rays);
    let spread = rays
        .iter()
        .map(|(_, o, d)| distance_to_line(&viewpoint, o, d))
        .fold(0.0, f64::max);
    let correspondences = in_frame(&rays, &UNIFIED_FRAME);
    // OCamCalib's frame is its own; its rays are turned into it once.
    let (rotation, ocam_rays) = match format {
        CameraFormat::Ocamcalib => (OCAM_FRAME, in_frame(&rays, &OCAM_FRAME)),
        _ => (UNIFIED_FRAME, Vec::new()),
    };
    let fit_error = |reason| ExportError::Fit {
        sensor: spec.name.clone(),
        reason,
    };
    let (model, residual) =
        fit_model(&sensor, format, &correspondences, &ocam_rays).map_err(fit_error)?;
    let pose = ModelPose {
        rotation,
        translation_mm: viewpoint,
    };
    let header = file_header(spec, format, &residual, spread, image_circle_px);
    let size = [sensor.width_px, sensor.height_px];
    let text = model_file(&model, format, size, &pose, &spec.name, &header);
    // The file must read back to the model that was fitted.
    check_read_back(&text, format, &residual, &correspondences, &ocam_rays).map_err(fit_error)?;
    let mut export = CameraExport {
        model,
        pose,
        residual,
        viewpoint_spread_mm: spread,
        image_circle_px,
        text,
        json: serde_json::Value::Null,
    };
    export.json = export_json(&spec.name, format, size, &export);
    Ok(export)
}

/// A traced ray: the pixel, the ray's origin and its unit direction (body frame, mm).
type Ray = ([f64; 2], Vector3<f64>, Vector3<f64>);

/// The ray of every pixel that sees the mirror, and the distance (px) from the principal
/// point of every one that does not.
fn traced_rays(sensor: &Sensor) -> (Vec<Ray>, Vec<f64>) {
    let mut rays = Vec::new();
    let mut dark_radii = Vec::new();
    for v in 0..sensor.height_px {
        for u in 0..sensor.width_px {
            match sensor.pixel_ray(u, v) {
                Some(r) => rays.push(([u as f64, v as f64], r.origin.coords, r.dir.normalize())),
                None => {
                    let (x, y) = sensor.image_coords(u, v);
                    dark_radii.push(x.hypot(y));
                }
            }
        }
    }
    (rays, dark_radii)
}

/// `rays` as pixel-direction pairs in a model's frame, whose axes are `rotation`'s columns.
fn in_frame(rays: &[Ray], rotation: &Matrix3<f64>) -> Vec<Correspondence> {
    rays.iter()
        .map(|(pixel, _, d)| Correspondence {
            direction: rotation.transpose() * d,
            pixel: *pixel,
        })
        .collect()
}

/// `format`'s model fitted to the rays, with its residual: the unified model (in its frame,
/// `correspondences`) first, the start of the double sphere fit and OCamCalib's centre
/// (`ocam_rays`: the rays in OCamCalib's frame).
fn fit_model(
    sensor: &Sensor,
    format: CameraFormat,
    correspondences: &[Correspondence],
    ocam_rays: &[Correspondence],
) -> Result<(FittedModel, FitResidual), VisionError> {
    let (unified, unified_residual) = fit_unified(correspondences)?;
    Ok(match format {
        CameraFormat::OpencvOmnidir | CameraFormat::KalibrOmni => {
            (FittedModel::Unified(unified), unified_residual)
        }
        CameraFormat::KalibrDs => {
            let (m, r) = fit_double_sphere(&unified, correspondences)?;
            (FittedModel::DoubleSphere(m), r)
        }
        CameraFormat::Ocamcalib => {
            let [cx, cy] = unified.principal_px;
            let size_hw = [sensor.height_px, sensor.width_px];
            let m = OcamModel::fit(ocam_rays, [cy, cx], size_hw, 4)?;
            let r = m.residual(ocam_rays);
            (FittedModel::Ocam(m), r)
        }
    })
}

/// The notes at the head of the file: the sensor, the model, the fit's residual, the rays'
/// spread about the viewpoint and the mirror's image.
fn file_header(
    spec: &SensorSpec,
    format: CameraFormat,
    residual: &FitResidual,
    spread: f64,
    image_circle_px: Option<f64>,
) -> String {
    format!(
        "omniloop: sensor {:?} ({} mirror) as the {} model, fitted to {} traced rays:\n\
         reprojection RMS {:.4} px, worst {:.4} px; rays within {:.3} mm of the viewpoint.\n\
         The mirror's image: {}.",
        spec.name,
        spec.optics.kind(),
        format.name(),
        residual.count,
        residual.rms_px,
        residual.worst_px,
        spread,
        image_circle_px.map_or("the whole image".to_string(), |r| format!(
            "a circle of radius {r:.4} px about the principal point"
        ))
    )
}

/// The file of `model` in `format` for sensor `sensor` (images `size` px, topic
/// `/camera/SENSOR` for Kalibr), `header` in its comments.
fn model_file(
    model: &FittedModel,
    format: CameraFormat,
    size: [u32; 2],
    pose: &ModelPose,
    sensor: &str,
    header: &str,
) -> String {
    let topic = format!("/camera/{sensor}");
    match model {
        FittedModel::Unified(m) if format == CameraFormat::KalibrOmni => {
            kalibr_omni_yaml(m, size, pose, &topic, header)
        }
        FittedModel::Unified(m) => opencv_omnidir_yaml(m, size, pose, header),
        FittedModel::DoubleSphere(m) => kalibr_ds_yaml(m, size, pose, &topic, header),
        // The toolbox reads its fields in a fixed order: the notes follow them.
        FittedModel::Ocam(m) => {
            let notes: String = header.lines().map(|l| format!("#{l}\n")).collect();
            format!("{}{notes}{}", m.calib_results_txt(), pose.comment_lines())
        }
    }
}

/// Checks that `text`, the file in `format`, reads back to a model with the fitted model's
/// `residual` over the same rays.
fn check_read_back(
    text: &str,
    format: CameraFormat,
    residual: &FitResidual,
    correspondences: &[Correspondence],
    ocam_rays: &[Correspondence],
) -> Result<(), VisionError> {
    let back = parse_camera_file(text, format.name()).map_err(|e| {
        VisionError::Calibration(format!(
            "the written {} file does not read back: {e}",
            format.name()
        ))
    })?;
    let back_residual = match &back {
        CameraFile::Unified(m, _) => reprojection(m, correspondences),
        CameraFile::DoubleSphere(m, _) => reprojection(m, correspondences),
        CameraFile::Ocam(m) => m.residual(ocam_rays),
    };
    if (back_residual.rms_px - residual.rms_px).abs() > 1e-6 {
        return Err(VisionError::Calibration(format!(
            "the written {} file reads back to a model with RMS {} px, not {} px",
            format.name(),
            back_residual.rms_px,
            residual.rms_px
        )));
    }
    Ok(())
}

/// The export as JSON (written beside the file): sensor, format, image size, intrinsics, the
/// model's frame in the body, the residual, the viewpoint spread and the image circle.
fn export_json(
    sensor: &str,
    format: CameraFormat,
    size: [u32; 2],
    e: &CameraExport,
) -> serde_json::Value {
    let (rotation, viewpoint) = (&e.pose.rotation, &e.pose.translation_mm);
    serde_json::json!({
        "sensor": sensor,
        "format": format.name(),
        "image_size_px": size,
        "intrinsics": e.model.json(),
        "model_frame_in_body": {
            "rotation": [
                [rotation[(0, 0)], rotation[(0, 1)], rotation[(0, 2)]],
                [rotation[(1, 0)], rotation[(1, 1)], rotation[(1, 2)]],
                [rotation[(2, 0)], rotation[(2, 1)], rotation[(2, 2)]],
            ],
            "translation_mm": [viewpoint.x, viewpoint.y, viewpoint.z],
        },
        "residual_px": {
            "rays": e.residual.count,
            "rms": e.residual.rms_px,
            "worst": e.residual.worst_px
        },
        "viewpoint_spread_mm": e.viewpoint_spread_mm,
        "image_circle_px": e.image_circle_px,
    })
}

/// The radius about the principal point halfway between the farthest pixel that sees the
/// mirror and the nearest dark one beyond it, or `None` when none is dark beyond it.
fn image_circle(sensor: &Sensor, rays: &[Ray], dark_radii: &[f64]) -> Option<f64> {
    let lit = rays
        .iter()
        .map(|(p, _, _)| {
            let (x, y) = sensor.image_coords(p[0] as u32, p[1] as u32);
            x.hypot(y)
        })
        .fold(0.0, f64::max);
    let dark = dark_radii
        .iter()
        .copied()
        .filter(|r| *r > lit)
        .fold(f64::INFINITY, f64::min);
    dark.is_finite().then_some(0.5 * (lit + dark))
}

/// The unified and double sphere models' frame in the body frame (its columns): x forward, y
/// right, z down.
const UNIFIED_FRAME: Matrix3<f64> = Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0);

/// OCamCalib's frame in the body frame: x along the image rows (the body's right), y along the
/// columns (forward), z up.
const OCAM_FRAME: Matrix3<f64> = Matrix3::new(0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0);

/// The point nearest (least squares) to the lines through `o` along unit `d`.
fn nearest_point(rays: &[Ray]) -> Vector3<f64> {
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    for (_, o, d) in rays {
        let p = Matrix3::identity() - d * d.transpose();
        a += p;
        b += p * o;
    }
    a.try_inverse().map_or(Vector3::zeros(), |inv| inv * b)
}

/// Distance from `p` to the line through `o` along unit `d`.
fn distance_to_line(p: &Vector3<f64>, o: &Vector3<f64>, d: &Vector3<f64>) -> f64 {
    let w = p - o;
    (w - d * w.dot(d)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pinhole_camera_is_not_exported() {
        let s =
            crate::load_scenario(std::path::Path::new("scenarios/render_pinhole.toml")).unwrap();
        let e = export_camera_model(&s.robot.sensors[0], CameraFormat::KalibrOmni).unwrap_err();
        assert!(e.to_string().contains("pinhole"), "{e}");
    }
}
