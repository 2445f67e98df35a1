//! Mei's unified camera model, as OpenCV's `omnidir` module and Kalibr's `omni` model use it.
//!
//! A point `P` in the model's frame (x right in the image, y down, z along the optical axis)
//! goes to the unit sphere, `P_s = P / |P|`, then through the plane at `z_s + xi`:
//! `m = (x_s / (z_s + xi), y_s / (z_s + xi))` (Mei and Rives 2007, eq. (5); Geyer and
//! Daniilidis' unifying model with `xi = 2e / (1 + e^2)` for a hyperbolic mirror of
//! eccentricity `e`); radial-tangential distortion
//! `m_d = m (1 + k1 r^2 + k2 r^4) + (2 p1 x y + p2 (r^2 + 2 x^2), p1 (r^2 + 2 y^2) + 2 p2 x y)`,
//! `r^2 = x^2 + y^2`; then pixels `u = f_x x_d + s y_d + c_x`, `v = f_y y_d + c_y`, with pixel
//! centres at integer coordinates (OpenCV's convention). This is `cv::omnidir::projectPoints`.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The unified model's intrinsics.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct UnifiedModel {
    /// Generalised focal lengths `f_x`, `f_y` (px).
    pub focal_px: [f64; 2],
    /// Skew `s` (px).
    pub skew_px: f64,
    /// Principal point `c_x`, `c_y` (px, pixel centres at integers).
    pub principal_px: [f64; 2],
    /// Mirror parameter `xi` (0 for a pinhole camera, 1 for a parabolic mirror).
    pub xi: f64,
    /// Distortion `[k1, k2, p1, p2]`.
    pub distortion: [f64; 4],
}

impl UnifiedModel {
    /// The model's nine free parameters in a fixed order: `f_x, f_y, c_x, c_y, xi, k1, k2, p1,
    /// p2` (the skew stays as it is).
    pub fn params(&self) -> [f64; 9] {
        let [fx, fy] = self.focal_px;
        let [cx, cy] = self.principal_px;
        let [k1, k2, p1, p2] = self.distortion;
        [fx, fy, cx, cy, self.xi, k1, k2, p1, p2]
    }

    /// The model with the parameters of [`UnifiedModel::params`].
    pub fn with_params(&self, p: &[f64; 9]) -> Self {
        Self {
            focal_px: [p[0], p[1]],
            skew_px: self.skew_px,
            principal_px: [p[2], p[3]],
            xi: p[4],
            distortion: [p[5], p[6], p[7], p[8]],
        }
    }

    /// The pixel `[u, v]` where the point `p` (model frame, any distance) images, or `None` for
    /// a point the model cannot image (`z_s + xi <= 0`, or at the origin).
    pub fn project(&self, p: &Vector3<f64>) -> Option<[f64; 2]> {
        let (x, y) = self.lift(&Self::on_sphere(p)?)?;
        Some(self.image(x, y))
    }

    /// `P_s = P / |P|`, or `None` at the origin or for a point not finite.
    pub(crate) fn on_sphere(p: &Vector3<f64>) -> Option<Vector3<f64>> {
        let n = p.norm();
        if n.is_nan() || n <= 0.0 || !n.is_finite() {
            return None;
        }
        Some(p / n)
    }

    /// `m = (x_s / (z_s + xi), y_s / (z_s + xi))` of a point on the unit sphere, or `None`
    /// where `z_s + xi <= 0` (eq. (5)).
    pub(crate) fn lift(&self, s: &Vector3<f64>) -> Option<(f64, f64)> {
        let denom = s.z + self.xi;
        if denom <= 1e-9 {
            return None;
        }
        Some((s.x / denom, s.y / denom))
    }

    /// The pixel of the undistorted normalised point `m = (x, y)`: the distortion, then the
    /// focal lengths, skew and principal point.
    pub(crate) fn image(&self, x: f64, y: f64) -> [f64; 2] {
        let [k1, k2, p1, p2] = self.distortion;
        let r2 = x * x + y * y;
        let radial = 1.0 + k1 * r2 + k2 * r2 * r2;
        let xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
        let yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
        let [fx, fy] = self.focal_px;
        let [cx, cy] = self.principal_px;
        [fx * xd + self.skew_px * yd + cx, fy * yd + cy]
    }

    /// The unit ray (model frame) of pixel `[u, v]`, or `None` where the model has no ray: the
    /// inverse of [`UnifiedModel::project`]. The distortion is undone by fixed-point iteration
    /// `m = (m_d - t(m)) / (1 + k1 r^2 + k2 r^4)` (as OpenCV's `undistortPoints`), and `None` is
    /// returned where it does not converge; then `m` is lifted to the sphere,
    /// `P_s = (l x, l y, l - xi)` with `l = (xi + sqrt(1 + (1 - xi^2) r^2)) / (1 + r^2)`
    /// (Mei and Rives 2007, eq. (6)), which has no real value where `1 + (1 - xi^2) r^2 < 0`.
    pub fn unproject(&self, pixel: [f64; 2]) -> Option<Vector3<f64>> {
        let [fx, fy] = self.focal_px;
        let [cx, cy] = self.principal_px;
        let yd = (pixel[1] - cy) / fy;
        let xd = (pixel[0] - cx - self.skew_px * yd) / fx;
        let [k1, k2, p1, p2] = self.distortion;
        let distort = |x: f64, y: f64| {
            let r2 = x * x + y * y;
            let radial = 1.0 + k1 * r2 + k2 * r2 * r2;
            let tx = 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
            let ty = p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
            (radial, tx, ty)
        };
        let (mut x, mut y) = (xd, yd);
        for _ in 0..UNDISTORT_ITERATIONS {
            let (radial, tx, ty) = distort(x, y);
            if radial.abs() < 1e-12 {
                return None;
            }
            (x, y) = ((xd - tx) / radial, (yd - ty) / radial);
        }
        let (radial, tx, ty) = distort(x, y);
        let miss = (x * radial + tx - xd).hypot(y * radial + ty - yd);
        if !miss.is_finite() || miss > 1e-9 * (1.0 + xd.hypot(yd)) {
            return None;
        }
        let r2 = x * x + y * y;
        let disc = 1.0 + (1.0 - self.xi * self.xi) * r2;
        if disc < 0.0 {
            return None;
        }
        let l = (self.xi + disc.sqrt()) / (1.0 + r2);
        if l <= 0.0 {
            return None;
        }
        Some(Vector3::new(l * x, l * y, l - self.xi).normalize())
    }
}

/// Fixed-point steps that undo the radial-tangential distortion (OpenCV's `undistortPoints`
/// takes 20 by default; the tracers take as many).
pub const UNDISTORT_ITERATIONS: usize = 20;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_on_the_axis_images_at_the_principal_point_and_scale_does_not_matter() {
        let m = UnifiedModel {
            focal_px: [300.0, 310.0],
            skew_px: 0.0,
            principal_px: [128.0, 110.0],
            xi: 0.9,
            distortion: [0.01, -0.002, 0.001, 0.0005],
        };
        let c = m.project(&Vector3::new(0.0, 0.0, 5.0)).unwrap();
        assert!((c[0] - 128.0).abs() < 1e-12 && (c[1] - 110.0).abs() < 1e-12);
        let a = m.project(&Vector3::new(1.0, -2.0, 0.5)).unwrap();
        let b = m.project(&Vector3::new(10.0, -20.0, 5.0)).unwrap();
        assert!((a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9);
        // Beyond what the model images: straight back from a mirror with xi < 1.
        assert!(m.project(&Vector3::new(0.0, 0.0, -1.0)).is_none());
        assert!(m.project(&Vector3::zeros()).is_none());
    }

    #[test]
    fn unproject_inverts_project_across_the_image() {
        let m = UnifiedModel {
            focal_px: [120.0, 118.0],
            skew_px: 0.3,
            principal_px: [127.5, 109.5],
            xi: 0.97,
            distortion: [0.01, -0.002, 0.001, 0.0005],
        };
        let mut checked = 0;
        for v in (0..220).step_by(7) {
            for u in (0..256).step_by(7) {
                let px = [u as f64, v as f64];
                let Some(d) = m.unproject(px) else { continue };
                assert!((d.norm() - 1.0).abs() < 1e-12);
                let back = m.project(&d).unwrap();
                let e = (back[0] - px[0]).hypot(back[1] - px[1]);
                assert!(e < 1e-6, "{e} px at {px:?}");
                checked += 1;
            }
        }
        assert!(checked > 1000, "{checked}");
        // xi > 1 leaves the image's outer part without rays.
        let wide = UnifiedModel {
            xi: 1.5,
            distortion: [0.0; 4],
            ..m
        };
        assert!(wide.unproject([127.5, 109.5]).is_some());
        assert!(wide.unproject([127.5 + 400.0, 109.5]).is_none());
    }

    #[test]
    fn without_distortion_a_pinhole_is_xi_zero() {
        let m = UnifiedModel {
            focal_px: [500.0, 500.0],
            skew_px: 0.0,
            principal_px: [320.0, 240.0],
            xi: 0.0,
            distortion: [0.0; 4],
        };
        let p = m.project(&Vector3::new(0.2, -0.1, 1.0)).unwrap();
        assert!((p[0] - 420.0).abs() < 1e-9 && (p[1] - 190.0).abs() < 1e-9);
    }
}
