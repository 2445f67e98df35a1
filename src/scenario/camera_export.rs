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
use omniloop_sim::SensorSpec;
use omniloop_sim::optics::Optics;
use omniloop_vision::camera_model::{
    Correspondence, FitResidual, ModelPose, UnifiedModel, fit_unified, kalibr_omni_yaml,
    opencv_omnidir_yaml,
};

/// A camera model file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraFormat {
    /// OpenCV `omnidir` (Mei's unified model: `K`, `xi`, `D`), a `cv::FileStorage` YAML.
    OpencvOmnidir,
    /// Kalibr's camchain YAML with `camera_model: omni`, `distortion_model: radtan`.
    KalibrOmni,
}

impl CameraFormat {
    /// Every format, by the name the command line takes.
    pub const ALL: [(&'static str, CameraFormat); 2] = [
        ("opencv-omnidir", CameraFormat::OpencvOmnidir),
        ("kalibr-omni", CameraFormat::KalibrOmni),
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
    #[error("sensor {sensor:?}: {source}")]
    Fit {
        /// The sensor.
        sensor: String,
        /// What failed.
        source: omniloop_vision::VisionError,
    },
}

/// A fitted model, its file's text and the figures of the fit.
#[derive(Debug, Clone)]
pub struct CameraExport {
    /// The fitted intrinsics.
    pub model: UnifiedModel,
    /// The model's frame on the robot.
    pub pose: ModelPose,
    /// Reprojection residual over every traced ray.
    pub residual: FitResidual,
    /// Largest distance (mm) of a ray from the model's viewpoint (0 for a central mirror).
    pub viewpoint_spread_mm: f64,
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
    let mut rays = Vec::new();
    for v in 0..sensor.height_px {
        for u in 0..sensor.width_px {
            if let Some(r) = sensor.pixel_ray(u, v) {
                rays.push(([u as f64, v as f64], r.origin.coords, r.dir.normalize()));
            }
        }
    }
    let viewpoint = nearest_point(&rays);
    let spread = rays
        .iter()
        .map(|(_, o, d)| distance_to_line(&viewpoint, o, d))
        .fold(0.0, f64::max);
    let rotation = Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0);
    let pose = ModelPose {
        rotation,
        translation_mm: viewpoint,
    };
    let correspondences: Vec<Correspondence> = rays
        .iter()
        .map(|(pixel, _, d)| Correspondence {
            direction: rotation.transpose() * d,
            pixel: *pixel,
        })
        .collect();
    let (model, residual) = fit_unified(&correspondences).map_err(|source| ExportError::Fit {
        sensor: spec.name.clone(),
        source,
    })?;
    let header = format!(
        "omniloop: sensor {:?} ({} mirror) as Mei's unified model, fitted to {} traced rays:\n\
         reprojection RMS {:.4} px, worst {:.4} px; rays within {:.3} mm of the viewpoint.",
        spec.name,
        spec.optics.kind(),
        residual.count,
        residual.rms_px,
        residual.worst_px,
        spread
    );
    let size = [sensor.width_px, sensor.height_px];
    let text = match format {
        CameraFormat::OpencvOmnidir => opencv_omnidir_yaml(&model, size, &pose, &header),
        CameraFormat::KalibrOmni => kalibr_omni_yaml(
            &model,
            size,
            &pose,
            &format!("/camera/{}", spec.name),
            &header,
        ),
    };
    let json = serde_json::json!({
        "sensor": spec.name,
        "format": format.name(),
        "model": "unified (Mei)",
        "image_size_px": size,
        "focal_px": model.focal_px,
        "skew_px": model.skew_px,
        "principal_point_px": model.principal_px,
        "xi": model.xi,
        "distortion_k1_k2_p1_p2": model.distortion,
        "model_frame_in_body": {
            "rotation": [
                [rotation[(0, 0)], rotation[(0, 1)], rotation[(0, 2)]],
                [rotation[(1, 0)], rotation[(1, 1)], rotation[(1, 2)]],
                [rotation[(2, 0)], rotation[(2, 1)], rotation[(2, 2)]],
            ],
            "translation_mm": [viewpoint.x, viewpoint.y, viewpoint.z],
        },
        "residual_px": { "rays": residual.count, "rms": residual.rms_px, "worst": residual.worst_px },
        "viewpoint_spread_mm": spread,
    });
    Ok(CameraExport {
        model,
        pose,
        residual,
        viewpoint_spread_mm: spread,
        text,
        json,
    })
}

/// The point nearest (least squares) to the lines through `o` along unit `d`.
fn nearest_point(rays: &[([f64; 2], Vector3<f64>, Vector3<f64>)]) -> Vector3<f64> {
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
    fn the_hyperbolic_mirror_is_central_and_the_unified_model_exact_for_it() {
        let spec = SensorSpec::corner_paper("omni");
        let e = export_camera_model(&spec, CameraFormat::OpencvOmnidir).unwrap();
        assert!(e.residual.count > 20_000, "{:?}", e.residual);
        assert!(e.residual.worst_px < 0.05, "{:?}", e.residual);
        assert!(e.viewpoint_spread_mm < 1e-6, "{}", e.viewpoint_spread_mm);
        // The viewpoint is the upper focus, 205.08 mm above the floor on the axis.
        let t = e.pose.translation_mm;
        assert!(t.xy().norm() < 1e-9 && (t.z - 205.08).abs() < 1e-9, "{t}");
        // xi = 2e / (1 + e^2) with e = c / b (Geyer and Daniilidis).
        let m = omniloop_sim::optics::HyperbolicMirror::corner_paper();
        let ecc = m.focal_half_distance_mm() / m.b_mm;
        assert!(
            (e.model.xi - 2.0 * ecc / (1.0 + ecc * ecc)).abs() < 1e-4,
            "{:?}",
            e.model
        );
    }

    #[test]
    fn a_pinhole_camera_is_not_exported() {
        let s =
            crate::load_scenario(std::path::Path::new("scenarios/render_pinhole.toml")).unwrap();
        let e = export_camera_model(&s.robot.sensors[0], CameraFormat::KalibrOmni).unwrap_err();
        assert!(e.to_string().contains("pinhole"), "{e}");
    }
}
