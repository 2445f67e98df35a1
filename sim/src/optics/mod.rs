//! Camera and mirror optics: for every pixel, the ray that leaves the sensor into the scene.
//!
//! Sensors look up at a mirror on the robot's vertical axis (hyperbolic, conical, spherical) or
//! out into the room (pinhole). Image coordinates: pixel `(u, v)` has its centre at
//! `X = u + 0.5 - c_x`, `Y = c_y - (v + 0.5)`; for the mirrors the camera ray is
//! `(X, Y, f)` in the robot frame (x forward, y left, z up), so a floor point at azimuth `phi`
//! images at image angle `Phi = phi` (eq. (2) of the corner paper) and `R = sqrt(X^2 + Y^2)`.
//!
//! Each mirror is an analytic ray-surface intersection with its normal; the reflected ray is
//! `r = d - 2 (d . n) n`. Rays that miss the mirror give `None` (black pixels). The same math
//! runs in the WGSL tracer (`render/trace.wgsl`).

pub mod conical;
pub mod hyperbolic;
pub mod pinhole;
pub mod spherical;

pub use conical::ConicalMirror;
pub use hyperbolic::HyperbolicMirror;
pub use pinhole::PinholeCamera;
pub use spherical::SphericalMirror;

use nalgebra::{Point3, Vector3};

/// A ray: origin and unit direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Origin.
    pub origin: Point3<f64>,
    /// Unit direction.
    pub dir: Vector3<f64>,
}

impl Ray {
    /// The point at parameter `t`.
    pub fn at(&self, t: f64) -> Point3<f64> {
        self.origin + self.dir * t
    }

    /// Where the ray meets the floor `z = 0`, if it goes down.
    pub fn floor_hit(&self) -> Option<Point3<f64>> {
        (self.dir.z < 0.0).then(|| self.at(-self.origin.z / self.dir.z))
    }
}

/// Mirror reflection: `d - 2 (d . n) n` for a unit normal `n`.
pub fn reflect(d: Vector3<f64>, n: Vector3<f64>) -> Vector3<f64> {
    d - n * (2.0 * d.dot(&n))
}

/// The roots of `a t^2 + b t + c = 0` in increasing order, computed without cancellation.
pub fn solve_quadratic(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    if a.abs() < 1e-300 {
        if b.abs() < 1e-300 {
            return None;
        }
        let t = -c / b;
        return Some((t, t));
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

/// The optics of one sensor.
#[derive(Debug, Clone, PartialEq)]
pub enum Optics {
    /// Single-viewpoint hyperboloidal mirror.
    Hyperbolic(HyperbolicMirror),
    /// Conical mirror (non-central).
    Conical(ConicalMirror),
    /// Spherical / hemispherical mirror (non-central).
    Spherical(SphericalMirror),
    /// Plain pinhole camera with pan and tilt.
    Pinhole(PinholeCamera),
}

impl Optics {
    /// The ray into the scene for image coordinates `(X, Y)` (pixels from the principal point,
    /// Y up), in the sensor frame: origin on the floor below the sensor's axis, z up.
    pub fn scene_ray(&self, x_px: f64, y_px: f64) -> Option<Ray> {
        match self {
            Optics::Hyperbolic(m) => m.scene_ray(x_px, y_px),
            Optics::Conical(m) => m.scene_ray(x_px, y_px),
            Optics::Spherical(m) => m.scene_ray(x_px, y_px),
            Optics::Pinhole(c) => c.scene_ray(x_px, y_px),
        }
    }

    /// The largest horizontal distance of a scene ray's origin from the sensor axis (the
    /// mirror's rim radius; 0 for a pinhole camera).
    pub fn max_origin_offset_mm(&self) -> f64 {
        match self {
            Optics::Hyperbolic(m) => m.rim_radius_mm,
            Optics::Conical(m) => m.radius_mm,
            Optics::Spherical(m) => m.radius_mm,
            Optics::Pinhole(_) => 0.0,
        }
    }

    /// Short name of the kind of optics.
    pub fn kind(&self) -> &'static str {
        match self {
            Optics::Hyperbolic(_) => "hyperbolic",
            Optics::Conical(_) => "conical",
            Optics::Spherical(_) => "spherical",
            Optics::Pinhole(_) => "pinhole",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_roots_are_ordered_and_accurate() {
        let (a, b) = solve_quadratic(1.0, -3.0, 2.0).unwrap();
        assert!((a - 1.0).abs() < 1e-15 && (b - 2.0).abs() < 1e-15);
        // Large b: the naive formula loses the small root.
        let (a, _) = solve_quadratic(1.0, -1e8, 1.0).unwrap();
        assert!((a - 1e-8).abs() < 1e-20);
        assert!(solve_quadratic(1.0, 0.0, 1.0).is_none());
    }

    #[test]
    fn reflection_preserves_length_and_flips_the_normal_component() {
        let n = Vector3::new(0.0, 0.0, 1.0);
        let r = reflect(Vector3::new(0.6, 0.0, -0.8), n);
        assert!((r - Vector3::new(0.6, 0.0, 0.8)).norm() < 1e-15);
    }
}
