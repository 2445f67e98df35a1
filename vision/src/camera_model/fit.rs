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
    /// The pixels of one point under each of `models`, into `out`: what
    /// [`Projection::project`] gives model by model, to the bit. The Jacobian projects every
    /// ray under `2n + 1` models that differ in one parameter each, so a model may compute
    /// once what depends on the point and the parameters the models share.
    fn project_each(models: &[Self], p: &Vector3<f64>, out: &mut [Option<[f64; 2]>]) {
        for (pixel, model) in out.iter_mut().zip(models) {
            *pixel = model.project(p);
        }
    }
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
    /// The point goes to the sphere once; through the plane at `z_s + xi` and the distortion
    /// once for the first model and again only for a model whose `xi` or distortion differs
    /// from the first's. The same operations in the same order as [`UnifiedModel::project`],
    /// so the same bits.
    fn project_each(models: &[Self], p: &Vector3<f64>, out: &mut [Option<[f64; 2]>]) {
        let (Some(s), Some(first)) = (UnifiedModel::on_sphere(p), models.first()) else {
            out.fill(None);
            return;
        };
        let shared = first.lift(&s);
        for (pixel, model) in out.iter_mut().zip(models) {
            let m = if model.xi.to_bits() == first.xi.to_bits() {
                shared
            } else {
                model.lift(&s)
            };
            *pixel = m.map(|(x, y)| model.image(x, y));
        }
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
/// `J^T J` is summed into its lower triangle, row after row of `J`, and mirrored at the end.
fn normal_equations<M: Projection>(
    model: &M,
    rays: &[Correspondence],
) -> (DMatrix<f64>, DVector<f64>) {
    let p = model.params();
    let n = p.len();
    let steps: Vec<f64> = p.iter().map(|v| 1e-6 * v.abs().max(1e-2)).collect();
    // The model, then each parameter moved up and down by its step.
    let mut models = vec![*model];
    for i in 0..n {
        for sign in [1.0, -1.0] {
            let mut q = p.clone();
            q[i] += sign * steps[i];
            models.push(model.with_params(&q));
        }
    }
    let mut pixels = vec![None; models.len()];
    let mut jtj = vec![0.0; n * n]; // column-major, as DMatrix
    let mut jtr = vec![0.0; n];
    let mut rows = [vec![0.0; n], vec![0.0; n]];
    for c in rays {
        M::project_each(&models, &c.direction, &mut pixels);
        let Some(base) = pixels[0] else {
            continue;
        };
        for row in rows.iter_mut() {
            row.fill(0.0);
        }
        for i in 0..n {
            // Central differences, one-sided at the edge of a parameter's range.
            let (a, b, span) = match (pixels[1 + 2 * i], pixels[2 + 2 * i]) {
                (Some(a), Some(b)) => (a, b, 2.0 * steps[i]),
                (Some(a), None) => (a, base, steps[i]),
                (None, Some(b)) => (base, b, steps[i]),
                (None, None) => continue,
            };
            for k in 0..2 {
                rows[k][i] = (a[k] - b[k]) / span;
            }
        }
        for (k, row) in rows.iter().enumerate() {
            for (j, (column, &rj)) in jtj.chunks_exact_mut(n).zip(row).enumerate() {
                for (sum, &ri) in column[j..].iter_mut().zip(&row[j..]) {
                    *sum += ri * rj;
                }
            }
            let r = base[k] - c.pixel[k];
            for (sum, &d) in jtr.iter_mut().zip(row) {
                *sum += r * d;
            }
        }
    }
    let mut jtj = DMatrix::from_vec(n, n, jtj);
    jtj.fill_upper_triangle_with_lower_triangle();
    (jtj, DVector::from_vec(jtr))
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
    fn projecting_under_many_models_at_once_gives_each_models_own_bits() {
        let base = UnifiedModel {
            focal_px: [420.0, 415.0],
            skew_px: 0.3,
            principal_px: [127.3, 109.1],
            xi: 0.97,
            distortion: [0.02, -0.004, 0.0006, -0.0003],
        };
        // The Jacobian's models: each parameter moved up and down, xi among them; then one
        // that images nothing below its horizon and one with xi back at the first's.
        let p = UnifiedModel::params(&base);
        let mut models = vec![base];
        for i in 0..9 {
            for step in [1e-6, -1e-6] {
                let mut q = p;
                q[i] += step * p[i].abs().max(1e-2);
                models.push(base.with_params(&q));
            }
        }
        models.push(UnifiedModel { xi: 0.0, ..base });
        models.push(UnifiedModel {
            focal_px: [1.0, 2.0],
            ..base
        });
        let mut points: Vec<Vector3<f64>> = rays_of(&base).iter().map(|c| c.direction).collect();
        points.extend([
            Vector3::zeros(),
            Vector3::new(f64::NAN, 0.0, 1.0),
            Vector3::new(f64::INFINITY, 0.0, 1.0),
            Vector3::new(0.3, -0.2, -0.97), // past the horizon of xi 0.97 but not of xi 1
            Vector3::new(1.0, 0.0, -0.97),  // z_s + xi near zero
            Vector3::new(-0.0, 0.0, 2.0),
        ]);
        let mut out = vec![None; models.len()];
        for point in &points {
            UnifiedModel::project_each(&models, point, &mut out);
            for (model, got) in models.iter().zip(&out) {
                let bits = |p: Option<[f64; 2]>| p.map(|[u, v]| [u.to_bits(), v.to_bits()]);
                assert_eq!(bits(*got), bits(model.project(point)), "{point} {model:?}");
            }
        }
    }

    #[test]
    fn too_few_rays_is_an_error() {
        let e = fit_unified(&[]).unwrap_err();
        assert!(e.to_string().contains("at least 20 rays"), "{e}");
    }
}
