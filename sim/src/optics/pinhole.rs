//! A plain pinhole camera on the robot, panned about the vertical and tilted about its own
//! horizontal axis (for forward-looking experiments).

use super::ray::Ray;
use nalgebra::{Point3, Vector3};
use omniloop_problem::{Problem, Problems};
use serde::{Deserialize, Serialize};

/// A pinhole camera looking out from the robot.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PinholeCamera {
    /// Focal length in pixels.
    pub focal_px: f64,
    /// Height of the pinhole above the floor.
    pub height_mm: f64,
    /// Rotation about the vertical from the robot's forward axis (counter-clockwise).
    #[serde(default)]
    pub pan_deg: f64,
    /// Elevation of the optical axis (negative looks down).
    #[serde(default)]
    pub tilt_deg: f64,
    /// Fastest the pan unit turns the camera when the robot commands a pan.
    #[serde(default = "default_pan_rate")]
    pub pan_rate_limit_deg_s: f64,
}

fn default_pan_rate() -> f64 {
    60.0
}

impl PinholeCamera {
    /// Its numbers that break a rule: the key and why.
    pub fn problems(&self) -> Vec<Problem> {
        let mut p = Problems::new();
        p.positive("focal_px", self.focal_px);
        p.positive("height_mm", self.height_mm);
        p.positive("pan_rate_limit_deg_s", self.pan_rate_limit_deg_s);
        if self.pan_deg.is_nan() || self.pan_deg.abs() > 180.0 {
            p.fail(
                "pan_deg",
                format!("must lie in [-180, 180] (got {})", self.pan_deg),
            );
        }
        if self.tilt_deg.is_nan() || self.tilt_deg.abs() > 90.0 {
            p.fail(
                "tilt_deg",
                format!("must lie in [-90, 90] (got {})", self.tilt_deg),
            );
        }
        p.into_vec()
    }

    /// Forward, right and up unit vectors of the camera in the robot frame.
    pub fn basis(&self) -> [Vector3<f64>; 3] {
        let (sp, cp) = self.pan_deg.to_radians().sin_cos();
        let (st, ct) = self.tilt_deg.to_radians().sin_cos();
        let forward = Vector3::new(cp * ct, sp * ct, st);
        let right = Vector3::new(sp, -cp, 0.0);
        let up = right.cross(&forward);
        [forward, right, up]
    }

    /// The scene ray for image coordinates `(X, Y)` (X right, Y up).
    pub fn scene_ray(&self, x_px: f64, y_px: f64) -> Option<Ray> {
        Some(self.ray_in(&self.basis(), x_px, y_px))
    }

    /// [`Self::scene_ray`] with the camera's [`Self::basis`] already worked out (`basis`): the
    /// same ray, to the bit, for a frame's every pixel at the cost of one basis.
    pub fn ray_in(&self, basis: &[Vector3<f64>; 3], x_px: f64, y_px: f64) -> Ray {
        let [f, r, u] = basis;
        let dir = (f * self.focal_px + r * x_px + u * y_px).normalize();
        Ray {
            origin: Point3::new(0.0, 0.0, self.height_mm),
            dir,
            path_mm: 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tilted_camera_sees_the_floor_ahead_at_the_principal_point() {
        let cam = PinholeCamera {
            focal_px: 300.0,
            height_mm: 100.0,
            pan_deg: 0.0,
            tilt_deg: -45.0,
            pan_rate_limit_deg_s: 60.0,
        };
        let hit = cam.scene_ray(0.0, 0.0).unwrap().floor_hit().unwrap();
        assert!((hit.x - 100.0).abs() < 1e-9 && hit.y.abs() < 1e-9);
        // Image right is robot right (-y).
        let hit = cam.scene_ray(50.0, 0.0).unwrap().floor_hit().unwrap();
        assert!(hit.y < 0.0);
        let panned = PinholeCamera {
            pan_deg: 90.0,
            ..cam
        };
        let hit = panned.scene_ray(0.0, 0.0).unwrap().floor_hit().unwrap();
        assert!(hit.x.abs() < 1e-9 && (hit.y - 100.0).abs() < 1e-9);
    }
}
