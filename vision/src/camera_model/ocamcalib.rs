//! Scaramuzza's polynomial model, as the OCamCalib toolbox writes it (`calib_results.txt`).
//!
//! A pixel at row `r`, column `c` gives `(x', y') = A^-1 (r - x_c, c - y_c)` with the affine
//! `A = [c d; e 1]`, and the ray `(x', y', f(rho))`, `rho = |(x', y')|`,
//! `f(rho) = a0 + a1 rho + a2 rho^2 + ...` with `a1 = 0` (Scaramuzza, Martinelli and Siegwart
//! 2006, eq. (6) and (11)): `cam2world` of the toolbox's `ocam_functions.c`. The way back,
//! `world2cam`, takes `theta = atan(z / |(x, y)|)` to `rho = sum invpol_i theta^i` and the
//! pixel `(x rho / |(x, y)|, y rho / |(x, y)|)` through `A` plus the centre. The model's frame:
//! x along the image rows (down), y along the columns (right), z = x cross y.
//!
//! Pixel coordinates here are 0-based with pixel centres at integers (as OpenCV's); the
//! toolbox's MATLAB side counts from 1, so its centre is ours plus one.

use super::fit::{Correspondence, FitResidual, residual_of};
use crate::VisionError;
use nalgebra::{DMatrix, DVector, Vector3};

/// Why a polynomial does not give every pixel of the image one ray
/// ([`OcamModel::check_polynomial`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PolynomialError {
    /// `a0` is 0.
    #[error("a0 is 0: the image centre has no ray")]
    NoCentreRay,
    /// `f` overflows within the image.
    #[error("f({rho_px:.1} px) is not a number")]
    NotANumber {
        /// Where, px from the centre.
        rho_px: f64,
    },
    /// The ray's elevation is not monotonic within the image.
    #[error(
        "f(rho) - rho tan(theta) has no real root in the image for elevations beyond \
         {beyond_deg:.2} deg: the ray's elevation turns back at rho = {rho_px:.1} px (the image \
         reaches {rho_max_px:.1} px)"
    )]
    TurnsBack {
        /// The last elevation reached before it turns, deg.
        beyond_deg: f64,
        /// Where it turns, px from the centre.
        rho_px: f64,
        /// The image's farthest corner, px from the centre.
        rho_max_px: f64,
    },
}

/// The OCamCalib model.
#[derive(Debug, Clone, PartialEq)]
pub struct OcamModel {
    /// `a0, a1, ...` of `f(rho)` (`a1 = 0`).
    pub pol: Vec<f64>,
    /// `rho(theta)`'s coefficients, for `world2cam`.
    pub invpol: Vec<f64>,
    /// Centre `(x_c, y_c)`: row, then column (px).
    pub center_rc: [f64; 2],
    /// Affine terms `c, d, e`.
    pub affine: [f64; 3],
    /// Image size: height, then width.
    pub size_hw: [u32; 2],
}

fn horner(coeffs: &[f64], x: f64) -> f64 {
    coeffs.iter().rev().fold(0.0, |acc, a| acc * x + a)
}

impl OcamModel {
    /// The ray (unit, model frame) of the pixel at `(row, col)`: `cam2world`.
    pub fn cam2world(&self, row: f64, col: f64) -> Vector3<f64> {
        let [c, d, e] = self.affine;
        let (dr, dc) = (row - self.center_rc[0], col - self.center_rc[1]);
        let inv = 1.0 / (c - d * e);
        let (xp, yp) = (inv * (dr - d * dc), inv * (-e * dr + c * dc));
        let rho = xp.hypot(yp);
        Vector3::new(xp, yp, horner(&self.pol, rho)).normalize()
    }

    /// The pixel `(row, col)` of a point of the model's frame: `world2cam`.
    pub fn world2cam(&self, p: &Vector3<f64>) -> [f64; 2] {
        let norm = p.x.hypot(p.y);
        if norm == 0.0 {
            return self.center_rc;
        }
        let rho = horner(&self.invpol, (p.z / norm).atan());
        let (x, y) = (p.x / norm * rho, p.y / norm * rho);
        let [c, d, e] = self.affine;
        [
            x * c + y * d + self.center_rc[0],
            x * e + y + self.center_rc[1],
        ]
    }

    /// Fits `f(rho)` of degree `degree` (with `a1 = 0`) to `rays` (directions in this model's
    /// frame, pixels as `[column, row]` = `[u, v]`) about the centre `center_rc`, no affine
    /// skew; then `invpol`, of the lowest degree (up to 16) that gives `f`'s pixels back within
    /// 0.01 px over the rays' range (or the closest, where none does).
    pub fn fit(
        rays: &[Correspondence],
        center_rc: [f64; 2],
        size_hw: [u32; 2],
        degree: usize,
    ) -> Result<Self, VisionError> {
        let samples: Vec<(f64, f64)> = rays
            .iter()
            .filter_map(|c| {
                let (xp, yp) = (c.pixel[1] - center_rc[0], c.pixel[0] - center_rc[1]);
                let rho = xp.hypot(yp);
                let dxy = c.direction.x.hypot(c.direction.y);
                (rho > 0.5 && dxy > 1e-9).then(|| (rho, rho * c.direction.z / dxy))
            })
            .collect();
        if samples.len() < 2 * degree {
            return Err(VisionError::Calibration(format!(
                "OCamCalib fit: {} usable rays for a polynomial of degree {degree}",
                samples.len()
            )));
        }
        let powers: Vec<usize> = std::iter::once(0).chain(2..=degree).collect();
        let free = least_squares(&samples, &powers)?;
        let mut pol = vec![0.0; degree + 1];
        for (p, a) in powers.iter().zip(free) {
            pol[*p] = a;
        }
        let rho_max = samples.iter().map(|s| s.0).fold(0.0, f64::max);
        let mut model = Self {
            pol,
            invpol: Vec::new(),
            center_rc,
            affine: [1.0, 0.0, 0.0],
            size_hw,
        };
        model.invpol = model.fit_inverse(rho_max)?;
        Ok(model)
    }

    /// `rho(theta)` through `(theta(rho), rho)` for `rho` from 0 to `rho_max`.
    fn fit_inverse(&self, rho_max: f64) -> Result<Vec<f64>, VisionError> {
        let grid: Vec<(f64, f64)> = (0..=2000)
            .map(|k| {
                let rho = rho_max * k as f64 / 2000.0;
                ((horner(&self.pol, rho) / rho.max(1e-9)).atan(), rho)
            })
            .collect();
        let mut best: Option<(f64, Vec<f64>)> = None;
        for degree in 2..=16 {
            let powers: Vec<usize> = (0..=degree).collect();
            let Ok(c) = least_squares(&grid, &powers) else {
                continue;
            };
            let worst = grid
                .iter()
                .map(|(t, r)| (horner(&c, *t) - r).abs())
                .fold(0.0, f64::max);
            if worst < 0.01 {
                return Ok(c);
            }
            if best.as_ref().is_none_or(|(w, _)| worst < *w) {
                best = Some((worst, c));
            }
        }
        // Not invertible to 0.01 px (a mirror whose f is not monotonic): the closest, which
        // the residual then reports.
        best.map(|(_, c)| c).ok_or_else(|| {
            VisionError::Calibration("OCamCalib fit: no inverse polynomial could be fitted".into())
        })
    }

    /// Whether `f(rho)` gives every pixel of the image one ray and every ray of the image one
    /// pixel: `a0 != 0` (else the centre pixel has no ray), and the ray's elevation
    /// `theta(rho) = atan(f(rho) / rho)` strictly monotonic from the centre pixel's rim
    /// (`rho = 1`) to the farthest corner, so that `world2cam`'s equation `f(rho) = rho tan(theta)` (Scaramuzza et al. 2006,
    /// eq. (6) solved for `rho`) has exactly one real root in the image for each `theta` in its
    /// field of view. The error says what fails, and where.
    pub fn check_polynomial(&self) -> Result<(), PolynomialError> {
        if self.pol.first().is_none_or(|a0| *a0 == 0.0) {
            return Err(PolynomialError::NoCentreRay);
        }
        let [h, w] = self.size_hw.map(f64::from);
        let rho_max = [(0.0, 0.0), (h, 0.0), (0.0, w), (h, w)]
            .iter()
            .map(|&(r, c)| self.rho(r - 0.5, c - 0.5))
            .fold(0.0, f64::max);
        let theta = |rho: f64| horner(&self.pol, rho).atan2(rho);
        const STEPS: usize = 1000;
        let mut sign = 0.0;
        let mut last = theta(1.0);
        for k in 1..=STEPS {
            let rho = 1.0 + (rho_max - 1.0) * k as f64 / STEPS as f64;
            let t = theta(rho);
            let step = t - last;
            if !t.is_finite() {
                return Err(PolynomialError::NotANumber { rho_px: rho });
            }
            if step == 0.0 || (sign != 0.0 && step.signum() != sign) {
                return Err(PolynomialError::TurnsBack {
                    beyond_deg: last.to_degrees(),
                    rho_px: rho,
                    rho_max_px: rho_max,
                });
            }
            sign = step.signum();
            last = t;
        }
        Ok(())
    }

    /// `rho` of the pixel at `(row, col)`: its distance from the centre after the affine map.
    fn rho(&self, row: f64, col: f64) -> f64 {
        let [c, d, e] = self.affine;
        let (dr, dc) = (row - self.center_rc[0], col - self.center_rc[1]);
        let inv = 1.0 / (c - d * e);
        (inv * (dr - d * dc)).hypot(inv * (-e * dr + c * dc))
    }

    /// The reprojection errors of `world2cam` on `rays` (pixels `[column, row]`).
    pub fn residual(&self, rays: &[Correspondence]) -> FitResidual {
        residual_of(rays, |c| {
            let [row, col] = self.world2cam(&c.direction);
            Some([col, row])
        })
    }

    /// The model as the toolbox's `calib_results.txt`.
    pub fn calib_results_txt(&self) -> String {
        let list = |v: &[f64]| {
            let items: Vec<String> = v.iter().map(|x| format!("{x:.12e}")).collect();
            format!("{} {} ", v.len(), items.join(" "))
        };
        let [c, d, e] = self.affine;
        format!(
            "#polynomial coefficients for the DIRECT mapping function (ocam_model.ss in MATLAB). These are used by cam2world\n\n{}\n\n\
             #polynomial coefficients for the inverse mapping function (ocam_model.invpol in MATLAB). These are used by world2cam\n\n{}\n\n\
             #center: \"row\" and \"column\", not \"x\" and \"y\"\n\n{:.6} {:.6}\n\n\
             #affine parameters \"c\", \"d\", and \"e\"\n\n{c:.6} {d:.6} {e:.6}\n\n\
             #image size: \"height\" and \"width\"\n\n{} {}\n\n",
            list(&self.pol),
            list(&self.invpol),
            self.center_rc[0],
            self.center_rc[1],
            self.size_hw[0],
            self.size_hw[1]
        )
    }
}

/// Least squares `y = sum_k c_k x^(powers_k)` over `(x, y)` samples.
fn least_squares(samples: &[(f64, f64)], powers: &[usize]) -> Result<Vec<f64>, VisionError> {
    let a = DMatrix::from_fn(samples.len(), powers.len(), |i, j| {
        samples[i].0.powi(powers[j] as i32)
    });
    let b = DVector::from_iterator(samples.len(), samples.iter().map(|s| s.1));
    let x = a
        .svd(true, true)
        .solve(&b, 1e-14)
        .map_err(|e| VisionError::Calibration(format!("polynomial fit: {e}")))?;
    Ok(x.iter().copied().collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> OcamModel {
        OcamModel {
            pol: vec![-110.0, 0.0, 3.6e-3, -2.1e-6, 1.4e-8],
            invpol: Vec::new(),
            center_rc: [109.5, 127.5],
            affine: [1.0, 0.0, 0.0],
            size_hw: [220, 256],
        }
    }

    #[test]
    fn its_own_rays_give_the_polynomial_and_pixels_back() {
        let truth = model();
        let mut rays = Vec::new();
        for row in (0..220).step_by(3) {
            for col in (0..256).step_by(3) {
                let d = truth.cam2world(row as f64, col as f64);
                rays.push(Correspondence {
                    direction: d,
                    pixel: [col as f64, row as f64],
                });
            }
        }
        let m = OcamModel::fit(&rays, truth.center_rc, truth.size_hw, 4).unwrap();
        for (a, b) in m.pol.iter().zip(&truth.pol) {
            assert!((a - b).abs() <= 1e-6 * b.abs().max(1e-6), "{:?}", m.pol);
        }
        for c in &rays {
            let p = m.world2cam(&c.direction);
            let e = (p[0] - c.pixel[1]).hypot(p[1] - c.pixel[0]);
            assert!(e < 0.02, "{e} at {:?}", c.pixel);
        }
        let text = m.calib_results_txt();
        let line = text.lines().nth(2).unwrap();
        let values: Vec<f64> = line
            .split_whitespace()
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(values.len(), 6, "{text}");
        assert_eq!(values[0], 5.0);
        for (a, b) in values[1..].iter().zip(&m.pol) {
            assert!((a - b).abs() <= 1e-11 * b.abs(), "{text}");
        }
        assert!(text.contains("\n\n109.500000 127.500000\n"), "{text}");
        assert!(text.contains("\n\n220 256\n"), "{text}");
    }
}
