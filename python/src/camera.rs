//! A robot's camera as a standard camera model, for software outside omniloop (a ROS 2
//! `camera_info`, OpenCV): the pinhole intrinsics of a pinhole camera, Mei's unified model
//! fitted to a mirror camera's traced rays (`omniloop calibrate --format opencv-omnidir`), and
//! where the model's frame sits on the robot.

use crate::convert::json_to_py;
use omniloop::camera_export::{CameraFormat, export_camera_model};
use omniloop_sim::SensorSpec;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::sync::{Mutex, PoisonError};

/// `spec`'s camera model as a dict: `sensor`, `image_size_px`, `intrinsics` (`model`:
/// `"pinhole"` or `"unified (Mei)"`, `focal_px`, `principal_point_px`; for a mirror also
/// `skew_px`, `xi`, `distortion_k1_k2_p1_p2`), `model_frame_in_body` (`rotation`, the
/// model frame's axes in the robot's body frame as columns, and `translation_mm`, its origin),
/// `pan_unit` (whether a pan unit turns it about the vertical) and, for one, `pan_rad` (the
/// scenario's pan, at which the rotation is given).
pub fn camera_model<'py>(py: Python<'py>, spec: &SensorSpec) -> PyResult<Bound<'py, PyAny>> {
    let json = match cached(spec) {
        Some(json) => json,
        None => {
            let json = py.detach(|| fitted(spec))?;
            FITTED
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .push((spec.clone(), json.clone()));
            json
        }
    };
    json_to_py(py, &json.to_string())
}

/// Models fitted in this process, by sensor: a mirror's fit takes seconds, and a team's robots
/// carry the same camera.
static FITTED: Mutex<Vec<(SensorSpec, serde_json::Value)>> = Mutex::new(Vec::new());

fn cached(spec: &SensorSpec) -> Option<serde_json::Value> {
    let fitted = FITTED.lock().unwrap_or_else(PoisonError::into_inner);
    fitted
        .iter()
        .find(|(s, _)| s == spec)
        .map(|(_, j)| j.clone())
}

/// `spec`'s model as JSON.
fn fitted(spec: &SensorSpec) -> PyResult<serde_json::Value> {
    Ok(match spec.optics.pinhole() {
        Some(p) => {
            let built = spec.build();
            let rotation = optical_axes(p.pan_deg.to_radians(), p.tilt_deg.to_radians());
            serde_json::json!({
                "sensor": spec.name,
                "image_size_px": [spec.width_px, spec.height_px],
                "intrinsics": {
                    "model": "pinhole",
                    "focal_px": [p.focal_px, p.focal_px],
                    "principal_point_px": [built.cx_px, built.cy_px],
                },
                "model_frame_in_body": {
                    "rotation": rotation,
                    "translation_mm": [spec.mount_mm[0], spec.mount_mm[1], p.height_mm],
                },
                "pan_unit": true,
                "pan_rad": p.pan_deg.to_radians(),
            })
        }
        None => {
            let export = export_camera_model(spec, CameraFormat::OpencvOmnidir)
                .map_err(|e| PyValueError::new_err(e.to_string()))?;
            let mut json = export.json;
            json["pan_unit"] = serde_json::Value::Bool(false);
            json
        }
    })
}

/// The optical frame of a pinhole camera panned by `pan` and tilted by `tilt` (rad), in the
/// body frame (x forward, y left, z up), as a row-major rotation whose columns are its axes:
/// z along the optical axis, x to the image's right (horizontal), y down the image (REP-103's
/// optical frame).
fn optical_axes(pan: f64, tilt: f64) -> [[f64; 3]; 3] {
    let z = [pan.cos() * tilt.cos(), pan.sin() * tilt.cos(), tilt.sin()];
    let x = [pan.sin(), -pan.cos(), 0.0];
    let y = [
        z[1] * x[2] - z[2] * x[1],
        z[2] * x[0] - z[0] * x[2],
        z[0] * x[1] - z[1] * x[0],
    ];
    [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]
}
