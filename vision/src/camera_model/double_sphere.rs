//! The double sphere camera model (Usenko, Demmel and Cremers 2018, eq. (40)-(43)), Kalibr's
//! `ds` camera: with `d1 = |P|` and `d2 = |(x, y, xi d1 + z)|`,
//! `u = f_x x / (alpha d2 + (1 - alpha)(xi d1 + z)) + c_x`, `v = f_y y / (...) + c_y`, a point
//! being imaged where `z > -w2 d1`, `w2 = (w1 + xi) / sqrt(2 w1 xi + xi^2 + 1)`,
//! `w1 = alpha / (1 - alpha)` if `alpha <= 0.5`, else `(1 - alpha) / alpha` (eq. (43)). Pixel
//! centres at integer coordinates. With `alpha = 0` it is Mei's unified model without
//! distortion.

use super::fit::{Correspondence, FitResidual, Projection, refine, residual};
use super::unified::UnifiedModel;
use crate::VisionError;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The double sphere model's intrinsics.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DoubleSphereModel {
    /// Focal lengths `f_x`, `f_y` (px).
    pub focal_px: [f64; 2],
    /// Principal point `c_x`, `c_y` (px).
    pub principal_px: [f64; 2],
    /// The shift `xi` between the two spheres.
    pub xi: f64,
    /// The weight `alpha` of the second sphere, in `[0, 1)`.
    pub alpha: f64,
}

impl DoubleSphereModel {
    /// The model equal to `m` where `m` has no distortion (`alpha = 0`).
    pub fn from_unified(m: &UnifiedModel) -> Self {
        Self {
            focal_px: m.focal_px,
            principal_px: m.principal_px,
            xi: m.xi,
            alpha: 0.0,
        }
    }
}

impl Projection for DoubleSphereModel {
    fn params(&self) -> Vec<f64> {
        let [fx, fy] = self.focal_px;
        let [cx, cy] = self.principal_px;
        vec![fx, fy, cx, cy, self.xi, self.alpha]
    }

    fn with_params(&self, p: &[f64]) -> Self {
        Self {
            focal_px: [p[0], p[1]],
            principal_px: [p[2], p[3]],
            xi: p[4],
            alpha: p[5],
        }
    }

    fn project(&self, p: &Vector3<f64>) -> Option<[f64; 2]> {
        let (xi, alpha) = (self.xi, self.alpha);
        if !(0.0..1.0).contains(&alpha) {
            return None;
        }
        let d1 = p.norm();
        let w1 = if alpha <= 0.5 {
            alpha / (1.0 - alpha)
        } else {
            (1.0 - alpha) / alpha
        };
        let w2 = (w1 + xi) / (2.0 * w1 * xi + xi * xi + 1.0).sqrt();
        if d1 <= 0.0 || p.z <= -w2 * d1 {
            return None;
        }
        let k = xi * d1 + p.z;
        let d2 = (p.x * p.x + p.y * p.y + k * k).sqrt();
        let denom = alpha * d2 + (1.0 - alpha) * k;
        if denom <= 1e-12 {
            return None;
        }
        let [fx, fy] = self.focal_px;
        let [cx, cy] = self.principal_px;
        Some([fx * p.x / denom + cx, fy * p.y / denom + cy])
    }
}

impl DoubleSphereModel {
    /// The unit ray (model frame) of pixel `[u, v]`, or `None` outside the model's image: with
    /// `m = ((u - c_x) / f_x, (v - c_y) / f_y)`, `r^2 = |m|^2`,
    /// `m_z = (1 - alpha^2 r^2) / (alpha sqrt(1 - (2 alpha - 1) r^2) + 1 - alpha)` and
    /// `P = (m_z xi + sqrt(m_z^2 + (1 - xi^2) r^2)) / (m_z^2 + r^2) (m_x, m_y, m_z) - (0, 0, xi)`
    /// (Usenko, Demmel and Cremers 2018, eq. (46)-(51)); valid where `alpha <= 0.5` or
    /// `r^2 <= 1 / (2 alpha - 1)`, and the square roots are real.
    pub fn unproject(&self, pixel: [f64; 2]) -> Option<Vector3<f64>> {
        let (xi, alpha) = (self.xi, self.alpha);
        let [fx, fy] = self.focal_px;
        let [cx, cy] = self.principal_px;
        let (mx, my) = ((pixel[0] - cx) / fx, (pixel[1] - cy) / fy);
        let r2 = mx * mx + my * my;
        let inner = 1.0 - (2.0 * alpha - 1.0) * r2;
        if inner < 0.0 {
            return None;
        }
        let mz = (1.0 - alpha * alpha * r2) / (alpha * inner.sqrt() + 1.0 - alpha);
        let disc = mz * mz + (1.0 - xi * xi) * r2;
        if disc < 0.0 {
            return None;
        }
        let k = (mz * xi + disc.sqrt()) / (mz * mz + r2);
        let p = Vector3::new(k * mx, k * my, k * mz - xi);
        let n = p.norm();
        (n.is_finite() && n > 0.0).then(|| p / n)
    }
}

/// The double sphere model fitted to `rays`: from the unified fit with the second sphere's
/// weight at a few values (xi grown until the model's field of view holds every ray), the best
/// refined one.
pub fn fit_double_sphere(
    unified: &UnifiedModel,
    rays: &[Correspondence],
) -> Result<(DoubleSphereModel, FitResidual), VisionError> {
    let mut best: Option<(DoubleSphereModel, FitResidual)> = None;
    for alpha in [0.0, 0.2, 0.4, 0.6] {
        let mut start = DoubleSphereModel {
            alpha,
            ..DoubleSphereModel::from_unified(unified)
        };
        while start.xi < 5.0 && !residual(&start, rays).rms_px.is_finite() {
            start.xi += 0.1;
        }
        if let Ok((m, r)) = refine(start, rays)
            && best.as_ref().is_none_or(|(_, b)| r.rms_px < b.rms_px)
        {
            best = Some((m, r));
        }
    }
    best.ok_or_else(|| {
        VisionError::Calibration("no start of the double sphere model images every ray".into())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn with_alpha_zero_it_is_the_unified_model() {
        let u = UnifiedModel {
            focal_px: [300.0, 300.0],
            skew_px: 0.0,
            principal_px: [128.0, 110.0],
            xi: 0.9,
            distortion: [0.0; 4],
        };
        let ds = DoubleSphereModel::from_unified(&u);
        for p in [
            Vector3::new(1.0, 2.0, 0.5),
            Vector3::new(-3.0, 0.2, -0.4),
            Vector3::new(0.1, -0.1, 2.0),
        ] {
            let (a, b) = (u.project(&p).unwrap(), ds.project(&p).unwrap());
            assert!((a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9);
        }
        // Straight back, beyond the model's field of view.
        assert!(ds.project(&Vector3::new(0.0, 0.0, -1.0)).is_none());
    }

    #[test]
    fn unproject_inverts_project_across_the_image() {
        let m = DoubleSphereModel {
            focal_px: [160.0, 158.0],
            principal_px: [127.5, 109.5],
            xi: -0.2,
            alpha: 0.6,
        };
        let mut checked = 0;
        for v in (0..220).step_by(7) {
            for u in (0..256).step_by(7) {
                let px = [u as f64, v as f64];
                let Some(d) = m.unproject(px) else { continue };
                let back = m.project(&d).unwrap();
                let e = (back[0] - px[0]).hypot(back[1] - px[1]);
                assert!(e < 1e-6, "{e} px at {px:?}");
                checked += 1;
            }
        }
        assert!(checked > 1000, "{checked}");
        // alpha > 0.5: beyond r^2 = 1 / (2 alpha - 1) there is no ray.
        assert!(m.unproject([127.5 + 160.0 * 2.3, 109.5]).is_none());
    }
}
