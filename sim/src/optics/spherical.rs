//! The spherical (hemispherical) mirror above a camera looking up (Kim et al., Sect. 2).
//!
//! A ball of radius `radius_mm` with its centre `camera_distance_mm` above the camera's pinhole;
//! the camera sees its lower half. Non-central: the scene rays do not share a viewpoint.

use super::ray::{Ray, reflect, solve_quadratic};
use nalgebra::{Point3, Vector3};
use omniloop_problem::{Problem, Problems};
use serde::{Deserialize, Serialize};

/// A spherical mirror above a camera looking up.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphericalMirror {
    /// Radius of the sphere.
    pub radius_mm: f64,
    /// Distance from the camera's pinhole up to the sphere's centre.
    pub camera_distance_mm: f64,
    /// Camera focal length in pixels.
    pub focal_px: f64,
    /// Height of the camera's pinhole above the floor.
    pub lens_height_mm: f64,
}

impl SphericalMirror {
    /// Its numbers that break a rule: the key and why.
    pub fn problems(&self) -> Vec<Problem> {
        let mut p = Problems::new();
        p.positive("radius_mm", self.radius_mm);
        p.positive("focal_px", self.focal_px);
        p.positive("lens_height_mm", self.lens_height_mm);
        if self.camera_distance_mm.is_nan() || self.camera_distance_mm <= self.radius_mm {
            let (r, d) = (self.radius_mm, self.camera_distance_mm);
            p.fail(
                "camera_distance_mm",
                format!("must exceed radius_mm = {r} (got {d})"),
            );
        }
        p.into_vec()
    }

    /// The scene ray for image coordinates `(X, Y)`; `None` when the camera ray misses the ball.
    pub fn scene_ray(&self, x_px: f64, y_px: f64) -> Option<Ray> {
        let d = Vector3::new(x_px, y_px, self.focal_px).normalize();
        let centre = Vector3::new(0.0, 0.0, self.camera_distance_mm);
        // |t d - centre|^2 = r^2.
        let b = -2.0 * d.dot(&centre);
        let c = centre.norm_squared() - self.radius_mm * self.radius_mm;
        let (t0, _) = solve_quadratic(1.0, b, c)?;
        if t0 <= 0.0 {
            return None;
        }
        let p = d * t0;
        let n = (p - centre) / self.radius_mm;
        Some(Ray {
            origin: Point3::new(p.x, p.y, p.z + self.lens_height_mm),
            dir: reflect(d, n),
            path_mm: t0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_centre_ray_is_reflected_straight_down_and_the_edge_grazes() {
        let m = SphericalMirror {
            radius_mm: 30.0,
            camera_distance_mm: 150.0,
            focal_px: 400.0,
            lens_height_mm: 100.0,
        };
        let ray = m.scene_ray(1e-6, 0.0).unwrap();
        assert!((ray.dir.z + 1.0).abs() < 1e-9);
        assert!((ray.origin.z - (100.0 + 120.0)).abs() < 1e-6);
        // The limb: sin(beta) = r / D.
        let limb = 400.0 * (30.0f64 / 150.0).asin().tan();
        assert!(m.scene_ray(limb - 0.05, 0.0).is_some());
        assert!(m.scene_ray(limb + 0.05, 0.0).is_none());
        // Reflection keeps the azimuth.
        let ray = m.scene_ray(30.0, 40.0).unwrap();
        assert!((ray.dir.y.atan2(ray.dir.x) - 40.0f64.atan2(30.0)).abs() < 1e-12);
        // Rays from the upper half of the visible cap point up and outward.
        let ray = m.scene_ray(limb - 1.0, 0.0).unwrap();
        assert!(ray.dir.z > 0.0 && ray.dir.x > 0.0);
    }
}
