//! The conical mirror: tip down toward a camera on its axis (Spacek and Burbridge, Sect. 2).
//!
//! The cone has its tip `tip_distance_mm` (d) above the camera's pinhole and opens upward to
//! the rim radius `radius_mm` (R). A camera ray at image radius h hits the surface
//! `rho = (z - d) tan(apex/2)`. For the 90 degree cone the reflected ray is
//! `z = d + (rho + d) h / v`, so a point at range r and height z above the lens images at
//! `h = v (z - d) / (r + d)`: two coaxial cones a distance s apart see it with radial disparity
//! `h1 - h2 = v s / (r + d)`, which is eq. (1) `r = v s / (h1 - h2) - d`, and the rim images at
//! `r_m = v R / (d + R)`, eq. (2) `v = (d / R + 1) r_m`.

use super::ray::{Ray, reflect};
use nalgebra::{Point3, Vector3};
use omniloop_problem::{Problem, Problems};
use serde::{Deserialize, Serialize};

/// A conical mirror above a camera looking up.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConicalMirror {
    /// Full angle at the cone's apex.
    #[serde(default = "default_apex")]
    pub apex_angle_deg: f64,
    /// Radius of the mirror's rim (R).
    pub radius_mm: f64,
    /// Distance from the camera's pinhole up to the cone's tip (d).
    pub tip_distance_mm: f64,
    /// Camera focal length in pixels (v).
    pub focal_px: f64,
    /// Height of the camera's pinhole above the floor.
    pub lens_height_mm: f64,
}

fn default_apex() -> f64 {
    90.0
}

impl ConicalMirror {
    /// Its numbers that break a rule: the key and why.
    pub fn problems(&self) -> Vec<Problem> {
        let mut p = Problems::new();
        if !(self.apex_angle_deg > 0.0 && self.apex_angle_deg < 180.0) {
            let why = format!("must lie in (0, 180) (got {})", self.apex_angle_deg);
            p.fail("apex_angle_deg", why);
        }
        p.positive("radius_mm", self.radius_mm);
        p.positive("tip_distance_mm", self.tip_distance_mm);
        p.positive("focal_px", self.focal_px);
        p.positive("lens_height_mm", self.lens_height_mm);
        p.into_vec()
    }

    /// The scene ray for image coordinates `(X, Y)`; `None` outside the rim.
    pub fn scene_ray(&self, x_px: f64, y_px: f64) -> Option<Ray> {
        let k = (self.apex_angle_deg.to_radians() / 2.0).tan();
        let d = Vector3::new(x_px, y_px, self.focal_px).normalize();
        let rho_d = (d.x * d.x + d.y * d.y).sqrt();
        // t rho_d = (t d_z - d) k  ->  t = k d / (k d_z - rho_d).
        let den = k * d.z - rho_d;
        if den <= 0.0 {
            return None;
        }
        let t = k * self.tip_distance_mm / den;
        let p = Point3::new(t * d.x, t * d.y, t * d.z);
        let rho = rho_d * t;
        if rho > self.radius_mm || rho < 1e-12 {
            return None;
        }
        // Normal of rho - k (z - d) = 0, pointing down and out toward the camera.
        let n = Vector3::new(p.x / rho, p.y / rho, -k).normalize();
        Some(Ray {
            origin: Point3::new(p.x, p.y, p.z + self.lens_height_mm),
            dir: reflect(d, n),
            path_mm: t,
        })
    }

    /// Image radius of the rim, `r_m = v R / (d + R)` for the 90 degree cone (eq. (2)).
    pub fn rim_image_radius_px(&self) -> f64 {
        let k = (self.apex_angle_deg.to_radians() / 2.0).tan();
        // The rim lies at rho = R, z = d + R / k above the lens.
        self.focal_px * self.radius_mm / (self.tip_distance_mm + self.radius_mm / k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cone() -> ConicalMirror {
        ConicalMirror {
            apex_angle_deg: 90.0,
            radius_mm: 30.0,
            tip_distance_mm: 100.0,
            focal_px: 500.0,
            lens_height_mm: 50.0,
        }
    }

    #[test]
    fn the_90_degree_cone_images_height_over_range_plus_d() {
        let m = cone();
        for h in [10.0, 40.0, 80.0, 110.0] {
            let ray = m.scene_ray(h, 0.0).unwrap();
            // h = v (z - d) / (r + d): at range r the ray is at height z = d + h (r + d) / v
            // above the lens.
            for r in [500.0, 1500.0, 3000.0] {
                let t = (r - ray.origin.x) / ray.dir.x;
                let z = ray.origin.z + t * ray.dir.z - m.lens_height_mm;
                let expected = m.tip_distance_mm + h * (r + m.tip_distance_mm) / m.focal_px;
                assert!(
                    (z - expected).abs() < 1e-9,
                    "h {h} r {r}: {z} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn rim_radius_follows_eq_2() {
        let m = cone();
        let rm = m.rim_image_radius_px();
        let v = (m.tip_distance_mm / m.radius_mm + 1.0) * rm;
        assert!((v - m.focal_px).abs() < 1e-9);
        assert!(m.scene_ray(rm - 0.01, 0.0).is_some());
        assert!(m.scene_ray(rm + 0.01, 0.0).is_none());
    }
}
