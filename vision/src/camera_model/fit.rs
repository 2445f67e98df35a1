//! Fitting a camera model to known rays: each ray's direction in the model's frame and the
//! pixel that sees it, by least squares on the reprojection error in pixels.
//!
//! A small Levenberg-Marquardt of our own (Marquardt's diagonal damping, a central-difference
//! Jacobian): the Rust crate for it is built on another major version of nalgebra than ours.

use super::unified::UnifiedModel;
use crate::VisionError;
use nalgebra::{DMatrix, DVector, Vector3};

/// A camera model the fit can adjust: its free parameters as a vector, and its projection.
pub trait Projection: Copy {
    /// The free parameters, in a fixed order.
    fn params(&self) -> Vec<f64>;
    /// The model with other values of [`Projection::params`].
    fn with_params(&self, p: &[f64]) -> Self;
    /// The pixel where a point of the model's frame images, if it does.
    fn project(&self, p: &Vector3<f64>) -> Option<[f64; 2]>;
}

impl Projection for UnifiedModel {
    fn params(&self) -> Vec<f64> {
        UnifiedModel::params(self).to_vec()
    }
    fn with_params(&self, p: &[f64]) -> Self {
        let mut q = [0.0; 9];
        q.copy_from_slice(&p[..9]);
        UnifiedModel::with_params(self, &q)
    }
    fn project(&self, p: &Vector3<f64>) -> Option<[f64; 2]> {
        UnifiedModel::project(self, p)
    }
}

/// A ray the model must image: its direction (model frame) and the pixel (pixel centres at
/// integer coordinates) that sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Correspondence {
    /// Direction of the ray from the model's viewpoint, in the model's frame.
    pub direction: Vector3<f64>,
    /// The pixel `[u, v]` that sees it.
    pub pixel: [f64; 2],
}

/// How well a fitted model reprojects its rays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitResidual {
    /// Rays the fit used.
    pub count: usize,
    /// Root mean square reprojection error (px).
    pub rms_px: f64,
    /// Largest reprojection error (px).
    pub worst_px: f64,
}

/// The reprojection errors of `model` on `rays` (a ray it cannot image counts as infinitely
/// far).
pub fn residual(model: &impl Projection, rays: &[Correspondence]) -> FitResidual {
    residual_of(rays, |c| model.project(&c.direction))
}

/// The reprojection errors of a projection given as a function of each ray: the pixel
/// `[u, v]` where it images the ray, if it does.
pub fn residual_of(
    rays: &[Correspondence],
    project: impl Fn(&Correspondence) -> Option<[f64; 2]>,
) -> FitResidual {
    let (mut sum, mut worst) = (0.0, 0.0f64);
    for c in rays {
        let e = match project(c) {
            Some(p) => (p[0] - c.pixel[0]).hypot(p[1] - c.pixel[1]),
            None => f64::INFINITY,
        };
        sum += e * e;
        worst = worst.max(e);
    }
    FitResidual {
        count: rays.len(),
        rms_px: (sum / rays.len().max(1) as f64).sqrt(),
        worst_px: worst,
    }
}

/// Fits the unified model (`f_x, f_y, c_x, c_y, xi` and the four distortion terms; no skew) to
/// `rays`. The start: for `xi` on a grid from 0 to 1.5, the focal lengths and principal point
/// without distortion by linear least squares, keeping the `xi` that fits best.
pub fn fit_unified(rays: &[Correspondence]) -> Result<(UnifiedModel, FitResidual), VisionError> {
    enough(rays)?;
    let start = (0..=30)
        .filter_map(|k| linear_start(rays, 0.05 * k as f64))
        .map(|m| (residual(&m, rays).rms_px, m))
        .filter(|(e, _)| e.is_finite())
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, m)| m)
        .ok_or_else(|| {
            VisionError::Calibration("no start for the unified model images every ray".into())
        })?;
    let model = levenberg_marquardt(start, rays);
    Ok((model, residual(&model, rays)))
}

/// Refines `start` on `rays` by least squares on the reprojection error.
pub fn refine<M: Projection>(
    start: M,
    rays: &[Correspondence],
) -> Result<(M, FitResidual), VisionError> {
    enough(rays)?;
    if !residual(&start, rays).rms_px.is_finite() {
        return Err(VisionError::Calibration(
            "the starting model does not image every ray".into(),
        ));
    }
    let model = levenberg_marquardt(start, rays);
    Ok((model, residual(&model, rays)))
}

fn enough(rays: &[Correspondence]) -> Result<(), VisionError> {
    if rays.len() < 20 {
        return Err(VisionError::Calibration(format!(
            "a camera model needs at least 20 rays to fit, got {}",
            rays.len()
        )));
    }
    Ok(())
}

/// Focal lengths and principal point for a given `xi`, without distortion: `u = f_x x + c_x`
/// and `v = f_y y + c_y` solved as two straight-line fits.
fn linear_start(rays: &[Correspondence], xi: f64) -> Option<UnifiedModel> {
    let mut sums = [[0.0f64; 5]; 2];
    for c in rays {
        let s = c.direction.normalize();
        let denom = s.z + xi;
        if denom <= 1e-6 {
            return None;
        }
        for (axis, sum) in sums.iter_mut().enumerate() {
            let (x, u) = (s[axis] / denom, c.pixel[axis]);
            *sum = [
                sum[0] + 1.0,
                sum[1] + x,
                sum[2] + u,
                sum[3] + x * x,
                sum[4] + x * u,
            ];
        }
    }
    let line = |[n, sx, su, sxx, sxu]: [f64; 5]| {
        let det = n * sxx - sx * sx;
        (det.abs() > 1e-12).then(|| ((n * sxu - sx * su) / det, (sxx * su - sx * sxu) / det))
    };
    let (fx, cx) = line(sums[0])?;
    let (fy, cy) = line(sums[1])?;
    Some(UnifiedModel {
        focal_px: [fx, fy],
        skew_px: 0.0,
        principal_px: [cx, cy],
        xi,
        distortion: [0.0; 4],
    })
}

/// Sum of squared reprojection errors; infinite where a ray cannot be imaged.
fn cost(model: &impl Projection, rays: &[Correspondence]) -> f64 {
    let r = residual(model, rays);
    r.rms_px * r.rms_px * r.count as f64
}

fn levenberg_marquardt<M: Projection>(start: M, rays: &[Correspondence]) -> M {
    let mut model = start;
    let mut current = cost(&model, rays);
    let mut lambda = 1e-3;
    let n = model.params().len();
    for _ in 0..200 {
        let (jtj, jtr) = normal_equations(&model, rays);
        let mut improved = false;
        while lambda < 1e12 {
            let mut a = jtj.clone();
            for i in 0..n {
                a[(i, i)] += lambda * jtj[(i, i)].max(1e-12);
            }
            let Some(step) = a.cholesky().map(|c| c.solve(&-&jtr)) else {
                lambda *= 4.0;
                continue;
            };
            let p = DVector::from_vec(model.params()) + step;
            let trial = model.with_params(p.as_slice());
            let c = cost(&trial, rays);
            if c < current {
                let gain = (current - c) / current.max(1e-300);
                model = trial;
                current = c;
                lambda = (lambda / 3.0).max(1e-12);
                improved = gain > 1e-14;
                break;
            }
            lambda *= 4.0;
        }
        if !improved {
            break;
        }
    }
    model
}

/// `J^T J` and `J^T r` of the reprojection residuals, with a central-difference Jacobian.
fn normal_equations<M: Projection>(
    model: &M,
    rays: &[Correspondence],
) -> (DMatrix<f64>, DVector<f64>) {
    let p = model.params();
    let n = p.len();
    let steps: Vec<f64> = p.iter().map(|v| 1e-6 * v.abs().max(1e-2)).collect();
    let shifted: Vec<[M; 2]> = (0..n)
        .map(|i| {
            [1.0, -1.0].map(|sign| {
                let mut q = p.clone();
                q[i] += sign * steps[i];
                model.with_params(&q)
            })
        })
        .collect();
    let mut jtj = DMatrix::<f64>::zeros(n, n);
    let mut jtr = DVector::<f64>::zeros(n);
    let mut rows = [DVector::<f64>::zeros(n), DVector::<f64>::zeros(n)];
    for c in rays {
        let Some(base) = model.project(&c.direction) else {
            continue;
        };
        for row in rows.iter_mut() {
            row.fill(0.0);
        }
        for (i, [plus, minus]) in shifted.iter().enumerate() {
            // Central differences, one-sided at the edge of a parameter's range.
            let (a, b, span) = match (plus.project(&c.direction), minus.project(&c.direction)) {
                (Some(a), Some(b)) => (a, b, 2.0 * steps[i]),
                (Some(a), None) => (a, base, steps[i]),
                (None, Some(b)) => (base, b, steps[i]),
                (None, None) => continue,
            };
            for k in 0..2 {
                rows[k][i] = (a[k] - b[k]) / span;
            }
        }
        for k in 0..2 {
            jtj.syger(1.0, &rows[k], &rows[k], 1.0);
            jtr.axpy(base[k] - c.pixel[k], &rows[k], 1.0);
        }
    }
    jtj.fill_upper_triangle_with_lower_triangle();
    (jtj, jtr)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rays of a known model over a fisheye-like field of view.
    fn rays_of(m: &UnifiedModel) -> Vec<Correspondence> {
        let mut out = Vec::new();
        for i in 0..40 {
            for j in 0..60 {
                let polar = 0.05 + 1.9 * i as f64 / 40.0;
                let az = std::f64::consts::TAU * j as f64 / 60.0;
                let d = Vector3::new(polar.sin() * az.cos(), polar.sin() * az.sin(), polar.cos());
                if let Some(pixel) = m.project(&d) {
                    out.push(Correspondence {
                        direction: d,
                        pixel,
                    });
                }
            }
        }
        out
    }

    #[test]
    fn a_models_own_rays_give_it_back() {
        let truth = UnifiedModel {
            focal_px: [420.0, 415.0],
            skew_px: 0.0,
            principal_px: [127.3, 109.1],
            xi: 0.97,
            distortion: [0.02, -0.004, 0.0006, -0.0003],
        };
        let rays = rays_of(&truth);
        let (m, r) = fit_unified(&rays).unwrap();
        assert!(r.worst_px < 1e-4, "{r:?}");
        assert!((m.xi - truth.xi).abs() < 1e-4, "{m:?}");
        assert!((m.focal_px[0] - truth.focal_px[0]).abs() < 0.05, "{m:?}");
    }

    #[test]
    fn too_few_rays_is_an_error() {
        let e = fit_unified(&[]).unwrap_err();
        assert!(e.to_string().contains("at least 20 rays"), "{e}");
    }
}
