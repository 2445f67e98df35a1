//! The paper's steps 2-7 as published (Sect. 4 of the corner paper): every outermost floor
//! pixel is a boundary point, the hull's moments give the first guess, the six lines of Fig. 6
//! are fitted by eq. (15).

use super::{
    BoundaryPoint, FieldFrame, FloorLocalizer, Localization, LocalizationMode, LocalizationQuality,
    PoseEstimate,
};
use crate::geometry::{Moments, convex_hull};
use image::RgbaImage;
use nalgebra::{Isometry2, Matrix3, Point2, Rotation2, Vector2, Vector3};

/// Step 6's outcome: the field's frame, the last fit's RMS residual (mm), the points and lines
/// it used, and the iterations run.
struct PaperFit {
    frame: FieldFrame,
    rms_mm: f64,
    points: usize,
    lines: usize,
    iterations: usize,
}

/// Why steps 3-6 found no frame of the field.
#[derive(Debug, thiserror::Error)]
enum PaperFailure {
    /// The boundary's hull is too small to be the field.
    #[error("floor region hull too small ({area_m2:.2} m^2)")]
    HullTooSmall {
        /// The hull's area, m^2.
        area_m2: f64,
    },
    /// The fit lost the lines that fix the field.
    #[error("boundary points do not fix the field (need a goal line or back and a touchline)")]
    Unfixed,
    /// The settings allow no iteration.
    #[error("no iteration of the fit ran (max_iterations is 0)")]
    NoIteration,
}

impl FloorLocalizer {
    /// Steps 2-7 on the prepared mask of `img`.
    pub(super) fn locate_paper(
        &self,
        img: &RgbaImage,
        hint: Option<&Isometry2<f64>>,
    ) -> Localization {
        // Steps 2 and 4.
        let points = self.boundary_points();
        if points.len() < 20 {
            return Localization::NotLocalized(format!(
                "too few floor boundary points ({})",
                points.len()
            ));
        }
        let fit = match self
            .first_guess(&points)
            .and_then(|guess| self.iterate_fit(&points, guess))
        {
            Ok(fit) => fit,
            Err(why) => return Localization::NotLocalized(why.to_string()),
        };
        let (chosen, other, by_goals) = self.choose(img, &fit.frame, hint);
        Localization::Localized(PoseEstimate {
            pose: chosen,
            alternative: other,
            quality: LocalizationQuality {
                rms_residual_mm: fit.rms_mm,
                points: fit.points,
                lines: fit.lines,
                points_per_line: Vec::new(),
                boundary_points: points.len(),
                inlier_fraction: fit.points as f64 / points.len() as f64,
                sigma: [f64::NAN; 3],
                hull_cut: false,
                iterations: fit.iterations,
                mode: LocalizationMode::Global,
                resolved_by_goals: by_goals,
            },
        })
    }

    /// Steps 3 (on the floor) and 5: the field's frame guessed from the moments of the
    /// boundary points' hull (its centroid and long axis); an error when the hull is too small
    /// to be the field.
    fn first_guess(&self, points: &[BoundaryPoint]) -> Result<FieldFrame, PaperFailure> {
        let pts: Vec<Point2<f64>> = points.iter().map(|b| b.p).collect();
        let hull = convex_hull(&pts);
        let m = Moments::of_polygon(&hull);
        let f = &self.config.field;
        let field_area = 4.0 * f.a1_mm * f.b_mm;
        if hull.len() < 3 || m.m00 < 0.1 * field_area {
            return Err(PaperFailure::HullTooSmall {
                area_m2: m.m00 * 1e-6,
            });
        }
        Ok(FieldFrame {
            centre: m.centroid(),
            psi: m.long_axis(),
        })
    }

    /// Step 6: from `guess`, the six lines fitted by eq. (15) and the frame moved by the fitted
    /// offset and rotation, until both are below the thresholds or the iterations run out.
    fn iterate_fit(
        &self,
        points: &[BoundaryPoint],
        guess: FieldFrame,
    ) -> Result<PaperFit, PaperFailure> {
        let FieldFrame {
            mut centre,
            mut psi,
        } = guess;
        let mut iterations = 0;
        let mut fit = None;
        while iterations < self.config.max_iterations {
            let gate = if iterations < 2 {
                self.config.gate_initial_mm
            } else {
                self.config.gate_mm
            };
            let Some((du, dv, zeta, rms, used, lines)) = self.fit_step(points, centre, psi, gate)
            else {
                return Err(PaperFailure::Unfixed);
            };
            iterations += 1;
            // Eqs. (16)-(18): move the estimate by the fitted offset and rotation.
            centre += Rotation2::new(psi) * Vector2::new(du, dv);
            psi += zeta;
            fit = Some((rms, used, lines));
            if du.abs() < self.config.offset_threshold_mm
                && dv.abs() < self.config.offset_threshold_mm
                && zeta.abs() < self.config.rotation_threshold_rad
            {
                break;
            }
        }
        let Some((rms_mm, points, lines)) = fit else {
            return Err(PaperFailure::NoIteration);
        };
        Ok(PaperFit {
            frame: FieldFrame { centre, psi },
            rms_mm,
            points,
            lines,
            iterations,
        })
    }

    /// Outermost floor pixels of each row and column, converted to the floor.
    fn boundary_points(&self) -> Vec<BoundaryPoint> {
        let (w, h) = (self.mask.width, self.mask.height);
        let r_max = self.config.max_radius_frac * self.cal.horizon_px;
        let [x0, y0, _, _] = self.region();
        // Mask pixel (u, v) is image pixel (u + x0, v + y0).
        let cx = self.cal.principal_point_px[0] - x0 as f64;
        let cy = self.cal.principal_point_px[1] - y0 as f64;
        let mut out = Vec::with_capacity(2 * (w + h));
        let mut push = |u: f64, v: f64| {
            // (u, v) in continuous mask coordinates (pixel k spans [k, k + 1)).
            let x = u - cx;
            let y = cy - v;
            let big_r = x.hypot(y);
            if big_r > r_max {
                return;
            }
            if let (Some(p), Some(slope)) = (
                self.cal.image_to_floor(x, y),
                self.cal.slope_mm_per_px(big_r),
            ) {
                out.push(BoundaryPoint::new(p, slope));
            }
        };
        for v in 1..h.saturating_sub(1) {
            let row = &self.mask.data[v * w..(v + 1) * w];
            if let (Some(a), Some(b)) = (
                row.iter().position(|&m| m != 0),
                row.iter().rposition(|&m| m != 0),
            ) {
                // A run touching the region's edge continues beyond it: not a boundary (and
                // beyond the usable radius anyway, unless the region is the image's edge).
                if a > 0 {
                    push(a as f64, v as f64 + 0.5);
                }
                if b + 1 < w {
                    push(b as f64 + 1.0, v as f64 + 0.5);
                }
            }
        }
        let columns = self.mask.column_extents();
        for (u, extent) in columns.iter().enumerate().take(w.saturating_sub(1)).skip(1) {
            if let Some((a, b)) = *extent {
                if a > 0 {
                    push(u as f64 + 0.5, a as f64);
                }
                if b + 1 < h {
                    push(u as f64 + 0.5, b as f64 + 1.0);
                }
            }
        }
        out
    }

    /// One step of eq. (15): assign points to lines in the current frame and solve the
    /// linearised weighted least squares for the field's offset (du, dv) and rotation zeta.
    #[allow(clippy::type_complexity)]
    pub(super) fn fit_step(
        &self,
        points: &[BoundaryPoint],
        centre: Point2<f64>,
        psi: f64,
        gate: f64,
    ) -> Option<(f64, f64, f64, f64, usize, usize)> {
        let f = &self.config.field;
        let (s, c) = psi.sin_cos();
        let mut ata = Matrix3::<f64>::zeros();
        let mut atb = Vector3::<f64>::zeros();
        let mut seen = [false; 6];
        let mut used = 0;
        let mut sum_w = 0.0;
        let mut sum_wd2 = 0.0;
        for bp in points {
            // Eqs. (13)-(14).
            let dx = bp.p.x - centre.x;
            let dy = bp.p.y - centre.y;
            let x = dx * c + dy * s;
            let y = -dx * s + dy * c;
            // Candidate lines as (index, signed distance, jacobian wrt (u, v, zeta)):
            // residual r = d0 + J . (u, v, zeta), linearised for small zeta. Each line takes
            // points along its extent plus `ends` beyond, so that near a corner both lines are
            // candidates and the nearer wins.
            let g = f.goal_half_width_mm;
            let ends = 0.5 * gate;
            let mut best: Option<(usize, f64, Vector3<f64>)> = None;
            let mut consider = |k: usize, d0: f64, j: Vector3<f64>| {
                if d0.abs() <= gate && best.is_none_or(|b| d0.abs() < b.1.abs()) {
                    best = Some((k, d0, j));
                }
            };
            if y.abs() <= g + ends {
                consider(0, x - f.a2_mm, Vector3::new(-1.0, 0.0, y));
                consider(3, -x - f.a2_mm, Vector3::new(1.0, 0.0, -y));
            }
            if y.abs() >= g - ends {
                consider(1, x - f.a1_mm, Vector3::new(-1.0, 0.0, y));
                consider(4, -x - f.a1_mm, Vector3::new(1.0, 0.0, -y));
            }
            if x.abs() <= f.a1_mm + ends {
                consider(2, y - f.b_mm, Vector3::new(0.0, -1.0, -x));
                consider(5, -y - f.b_mm, Vector3::new(0.0, 1.0, x));
            }
            let Some((k, d0, j)) = best else { continue };
            seen[k] = true;
            used += 1;
            ata += j * j.transpose() * bp.w;
            atb -= j * (d0 * bp.w);
            sum_w += bp.w;
            sum_wd2 += bp.w * d0 * d0;
        }
        let lines = seen.iter().filter(|&&s| s).count();
        let along_x = seen[0] || seen[1] || seen[3] || seen[4];
        let along_y = seen[2] || seen[5];
        if !(along_x && along_y) || used < 10 {
            return None;
        }
        let sol = ata.lu().solve(&atb)?;
        Some((sol.x, sol.y, sol.z, (sum_wd2 / sum_w).sqrt(), used, lines))
    }
}
