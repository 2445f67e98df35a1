//! The single-viewpoint hyperboloidal mirror.
//!
//! Mirror: the upper sheet of `Z^2/b^2 - (X^2 + Y^2)/a^2 = 1` with foci at `Z = +-c`,
//! `c^2 = a^2 + b^2`; the camera's pinhole sits at the lower focus looking up, so every scene
//! ray it sees passes through the upper focus, the single viewpoint, `focus_height_mm` above
//! the floor. For such a mirror the image-to-floor map has the form
//! `r = f(R) = R / (A - B sqrt(C + R^2))` (Sect. 5 of the corner paper, model of Yagi [6]).

use super::ray::{Ray, reflect, solve_quadratic};
use nalgebra::{Point3, Vector3};
use omniloop_problem::{Problem, Problems};
use serde::{Deserialize, Serialize};

/// A hyperboloidal mirror with its camera at the outer focus.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HyperbolicMirror {
    /// a: the hyperboloid's transverse radius parameter.
    pub a_mm: f64,
    /// b: the hyperboloid's axial parameter.
    pub b_mm: f64,
    /// c: half the distance between the foci. It must equal `sqrt(a^2 + b^2)` to within 0.1%
    /// (checked when the scenario is loaded); the optics use the exact `sqrt(a^2 + b^2)`.
    pub c_mm: f64,
    /// Camera focal length in pixels.
    pub focal_px: f64,
    /// Height of the upper focus (the viewpoint) above the floor.
    pub focus_height_mm: f64,
    /// Radius of the mirror's rim; camera rays beyond it miss the mirror.
    pub rim_radius_mm: f64,
}

impl HyperbolicMirror {
    /// Its numbers that break a rule: the key and why.
    pub fn problems(&self) -> Vec<Problem> {
        let mut p = Problems::new();
        for (k, v) in [
            ("a_mm", self.a_mm),
            ("b_mm", self.b_mm),
            ("c_mm", self.c_mm),
            ("focal_px", self.focal_px),
            ("focus_height_mm", self.focus_height_mm),
            ("rim_radius_mm", self.rim_radius_mm),
        ] {
            p.positive(k, v);
        }
        let exact = self.a_mm.hypot(self.b_mm);
        if (self.c_mm - exact).abs() > 1e-3 * exact {
            let got = self.c_mm;
            let why =
                format!("must equal sqrt(a^2 + b^2) = {exact:.4} mm to within 0.1% (got {got})");
            p.fail("c_mm", why);
        }
        if self.focus_height_mm <= 2.0 * exact {
            p.fail(
                "focus_height_mm",
                "puts the camera (2 c below the focus) under the floor",
            );
        }
        p.into_vec()
    }

    /// The mirror reconstructed from the corner paper's calibration (`docs/experiments.md`):
    /// f = sqrt(C) = 479.37 px, b/c = 0.79040, c = 19.8 mm, viewpoint 205.08 mm above the floor.
    pub fn corner_paper() -> Self {
        Self {
            a_mm: 12.129,
            b_mm: 15.650,
            c_mm: 19.8,
            focal_px: 479.37,
            focus_height_mm: 205.08,
            rim_radius_mm: 30.0,
        }
    }

    /// The exact focal half-distance `sqrt(a^2 + b^2)`.
    pub fn focal_half_distance_mm(&self) -> f64 {
        self.a_mm.hypot(self.b_mm)
    }

    /// Height of the camera's pinhole (the lower focus) above the floor.
    pub fn lens_height_mm(&self) -> f64 {
        self.focus_height_mm - 2.0 * self.focal_half_distance_mm()
    }

    /// Height of the hyperboloid's centre above the floor.
    fn centre_height_mm(&self) -> f64 {
        self.focus_height_mm - self.focal_half_distance_mm()
    }

    /// The scene ray for image coordinates `(X, Y)`; `None` outside the rim.
    pub fn scene_ray(&self, x_px: f64, y_px: f64) -> Option<Ray> {
        let (a, b, c) = (self.a_mm, self.b_mm, self.focal_half_distance_mm());
        let d = Vector3::new(x_px, y_px, self.focal_px).normalize();
        // Camera at (0, 0, -c) in the mirror's frame: substitute p = (0,0,-c) + t d into
        // Z^2/b^2 - rho^2/a^2 = 1, times b^2.
        let rho2 = d.x * d.x + d.y * d.y;
        let qa = d.z * d.z - rho2 * b * b / (a * a);
        let qb = -2.0 * c * d.z;
        let qc = c * c - b * b;
        let (t0, t1) = solve_quadratic(qa, qb, qc)?;
        // The first crossing of the upper sheet (Z > 0) in front of the camera.
        let t = [t0, t1]
            .into_iter()
            .find(|&t| t > 0.0 && -c + t * d.z > 0.0)?;
        let p = Point3::new(t * d.x, t * d.y, -c + t * d.z);
        if p.x * p.x + p.y * p.y > self.rim_radius_mm * self.rim_radius_mm {
            return None;
        }
        // Normal: gradient of Z^2/b^2 - (X^2 + Y^2)/a^2, pointing toward the camera side.
        let n = Vector3::new(p.x / (a * a), p.y / (a * a), -p.z / (b * b)).normalize();
        let r = reflect(d, n);
        Some(Ray {
            origin: Point3::new(p.x, p.y, p.z + self.centre_height_mm()),
            dir: r,
            path_mm: t,
        })
    }

    /// The constants `(A, B, C)` of the paper's image-to-floor map
    /// `r = f(R) = R / (A - B sqrt(C + R^2))` that this mirror has in closed form.
    ///
    /// A floor point at distance r lies `H` = `focus_height_mm` below the viewpoint and images
    /// at `R = r f a^2 / ((b^2 + c^2) H + 2 b c sqrt(r^2 + H^2))` (the HyperOmni projection of
    /// Yamazawa and Yagi). Solving for r, using `(b^2 + c^2)^2 - (2 b c)^2 = a^4`, gives
    /// `A = f (b^2 + c^2) / (H a^2)`, `B = 2 b c / (H a^2)`, `C = f^2`.
    pub fn closed_form_abc(&self) -> (f64, f64, f64) {
        let (a, b, c, f, h) = (
            self.a_mm,
            self.b_mm,
            self.focal_half_distance_mm(),
            self.focal_px,
            self.focus_height_mm,
        );
        let k = h * a * a;
        (f * (b * b + c * c) / k, 2.0 * b * c / k, f * f)
    }

    /// `r = f(R)` in closed form (floor distance in mm for image radius R in pixels), or
    /// `None` at and beyond the horizon.
    pub fn floor_distance_mm(&self, r_px: f64) -> Option<f64> {
        let (a, b, c) = self.closed_form_abc();
        let den = a - b * (c + r_px * r_px).sqrt();
        (den > 0.0).then(|| r_px / den)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_corner_paper_mirror_has_the_papers_constants() {
        let m = HyperbolicMirror::corner_paper();
        assert!((m.a_mm.powi(2) + m.b_mm.powi(2) - m.c_mm.powi(2)).abs() < 0.01);
        let (a, b, c) = m.closed_form_abc();
        assert!((a / 10.12 - 1.0).abs() < 1e-3, "A = {a}");
        assert!((b / 2.054e-2 - 1.0).abs() < 1e-3, "B = {b}");
        assert!((c / 2.298e5 - 1.0).abs() < 1e-3, "C = {c}");
        assert!((m.lens_height_mm() - 165.48).abs() < 0.01);
    }

    #[test]
    fn every_scene_ray_passes_through_the_viewpoint() {
        let m = HyperbolicMirror::corner_paper();
        let focus = Point3::new(0.0, 0.0, m.focus_height_mm);
        for (x, y) in [(3.0, 1.0), (40.0, -20.0), (-80.0, 60.0), (0.5, 110.0)] {
            let ray = m.scene_ray(x, y).unwrap();
            // Distance from the focus to the ray's line.
            let v = focus - ray.origin;
            let dist = (v - ray.dir * v.dot(&ray.dir)).norm();
            assert!(dist < 1e-9, "({x}, {y}): {dist}");
            // The ray leaves the mirror away from the focus, at the image angle.
            assert!(v.dot(&ray.dir) < 0.0);
            let phi = ray.dir.y.atan2(ray.dir.x);
            assert!((phi - y.atan2(x)).abs() < 1e-12);
        }
    }

    #[test]
    fn traced_floor_distances_match_the_closed_form() {
        let m = HyperbolicMirror::corner_paper();
        for k in 1..=110 {
            let r_px = k as f64;
            let ray = m.scene_ray(r_px, 0.0).unwrap();
            let hit = ray.floor_hit().unwrap();
            let r = m.floor_distance_mm(r_px).unwrap();
            assert!(
                (hit.x - r).abs() < 1e-6 * r.max(1.0),
                "R = {r_px}: {} vs {r}",
                hit.x
            );
        }
        // Beyond the horizon (R about 114 px) rays go up.
        assert!(m.floor_distance_mm(115.0).is_none());
        assert!(m.scene_ray(115.0, 0.0).unwrap().dir.z > 0.0);
    }
}
