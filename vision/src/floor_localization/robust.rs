//! This project's localization method (see the parent module for how it differs from the
//! paper's): boundary points where the floor meets a wall or a goal, a twelve-segment field
//! model fitted by eq. (15), a first guess from the prior (tracking) or from a search (global),
//! and a decision rule.

use super::{
    BoundaryPoint, FieldFrame, FieldModel, FloorLocalizer, Localization, LocalizationMode,
    LocalizationQuality, PoseEstimate,
};
use image::RgbaImage;
use nalgebra::{Isometry2, Matrix3, Point2, Rotation2, Vector2, Vector3};
use std::f64::consts::{FRAC_PI_2, PI};

/// Fewest boundary points to try at all.
const MIN_BOUNDARY_POINTS: usize = 20;
/// Two first guesses that converge this close (and this little turned, modulo a half turn)
/// found the same field.
const SAME_MM: f64 = 100.0;
const SAME_RAD: f64 = 0.087;
/// Another pose explaining this share of the best one's points makes the image ambiguous.
const AMBIGUOUS_SHARE: f64 = 0.9;
/// Tracking looks for the field this far from the prior when the fit from the prior fails.
const TRACKING_REACH_MM: f64 = 400.0;
const TRACKING_REACH_RAD: f64 = 0.35;
/// A point is assigned to a segment within the gate or within this many of its pixels.
const GATE_PIXELS: f64 = 2.0;
/// Global first guesses refined further, the best by their first step.
const TRIALS: usize = 6;
/// Iterations each global first guess gets before they are compared.
const TRIAL_ITERATIONS: usize = 3;

/// One step of eq. (15) over the segments.
#[derive(Debug, Clone)]
struct Step {
    /// Offset (du, dv) and rotation zeta of the field.
    delta: Vector3<f64>,
    /// Weighted RMS of the assigned points' distances, mm.
    rms_mm: f64,
    /// Points assigned.
    used: usize,
    /// Points assigned to each segment.
    per_segment: [usize; Model::SEGMENTS],
    /// The share of the points that are assigned, of all but those seen past a goal post.
    explained: f64,
    /// Standard deviations of (du, dv, zeta) from the least squares.
    sigma: [f64; 3],
}

/// What lies just beyond the outermost floor pixel of a row or column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Beyond {
    /// A wall or a goal: the field's boundary.
    Boundary,
    /// More floor: the analysed image ends there.
    Cut,
    /// Anything else: a cube, a robot, the robot's own body.
    Occluder,
}

/// A sector of the image: azimuths `from..to` (rad, image angle about the principal point)
/// and radii `r_in..r_out` (px).
struct GoalSector {
    from: f64,
    to: f64,
    r_in: f64,
    r_out: f64,
}

/// The boundary points of an image.
struct WallPoints {
    points: Vec<BoundaryPoint>,
    /// Whether the floor ran on past the analysed image's edge somewhere.
    cut: bool,
    /// The directions between neighbouring points.
    directions: Directions,
}

/// The boundary's direction modulo a quarter turn, from the steps between boundary points
/// [`Directions::BASE`] rows (or columns) apart on the same side: each step `d` at angle `phi`
/// adds `|d| (cos 4 phi, sin 4 phi)`, so that steps along either of two perpendicular walls add
/// up, and the sum's angle over four is the walls' direction. (Steps between neighbouring rows
/// are too short: the pixel staircase turns them by several degrees.)
#[derive(Debug, Default, Clone, Copy)]
struct Directions {
    c4: f64,
    s4: f64,
    total: f64,
}

impl Directions {
    /// Rows or columns between the two ends of a step.
    const BASE: usize = 6;
    /// Steps longer than this jump between walls or across a gap, mm.
    const MAX_STEP_MM: f64 = 400.0;
    /// The sum must be at least this share of the steps' length: the steps agree.
    const MIN_AGREEMENT: f64 = 0.5;

    fn add(&mut self, d: Vector2<f64>) {
        let l2 = d.norm_squared();
        if l2 <= 0.0 || l2 > Self::MAX_STEP_MM * Self::MAX_STEP_MM {
            return;
        }
        // Double angles of the unit step, then of those.
        let (c2, s2) = ((d.x * d.x - d.y * d.y) / l2, 2.0 * d.x * d.y / l2);
        let l = l2.sqrt();
        self.c4 += l * (c2 * c2 - s2 * s2);
        self.s4 += l * 2.0 * c2 * s2;
        self.total += l;
    }

    /// The walls' direction in [0, pi/2), if the steps agree on one.
    fn angle(&self) -> Option<f64> {
        let agreement = self.c4.hypot(self.s4);
        (self.total > 0.0 && agreement >= Self::MIN_AGREEMENT * self.total)
            .then(|| (self.s4.atan2(self.c4) / 4.0).rem_euclid(FRAC_PI_2))
    }
}

/// Why the robust fit found no pose (reported as [`Localization::NotLocalized`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub(super) enum FitFailure {
    /// Tracking: the fit from the best guess near the prior did not converge.
    #[error("the fit near the prior did not converge")]
    NearPrior,
    /// Tracking: no guess came near the prior, and the fit from the prior did not converge.
    #[error("the fit from the prior did not converge")]
    FromPrior,
    /// Global: no first guess converged.
    #[error("no first guess converged to a field the boundary fits")]
    NoGuess,
    /// Global: the best first guess did not converge when finished.
    #[error("the best first guess did not converge")]
    BestGuess,
    /// Global: another pose explains nearly as much of the boundary.
    #[error(
        "ambiguous: another pose ({x_mm:.0}, {y_mm:.0}, {heading_deg:.0} deg) explains \
         {rival_percent:.0}% of the boundary against {best_percent:.0}%"
    )]
    Ambiguous {
        /// The other pose's x, mm.
        x_mm: f64,
        /// The other pose's y, mm.
        y_mm: f64,
        /// The other pose's heading, deg.
        heading_deg: f64,
        /// The share of the boundary the other pose explains, %.
        rival_percent: f64,
        /// The share the best pose explains, %.
        best_percent: f64,
    },
}

impl FloorLocalizer {
    /// The robust method on the prepared mask: tracking from `prior` when given, else global;
    /// `hint` chooses between the two solutions when no goal is seen.
    pub(super) fn locate_robust(
        &self,
        img: &RgbaImage,
        prior: Option<&Isometry2<f64>>,
        hint: Option<&Isometry2<f64>>,
    ) -> Localization {
        let WallPoints {
            points,
            cut: hull_cut,
            directions,
        } = self.wall_points(img);
        if points.len() < MIN_BOUNDARY_POINTS {
            return Localization::NotLocalized(format!(
                "too few points where the floor meets a wall or a goal ({}, need \
                 {MIN_BOUNDARY_POINTS})",
                points.len()
            ));
        }
        let model = Model::new(&self.config.field);
        let (mode, found) = match prior {
            Some(p) => (
                LocalizationMode::Tracking,
                self.track_from(&points, &model, p, hull_cut),
            ),
            None => (
                LocalizationMode::Global,
                self.search(&points, &model, directions.angle()),
            ),
        };
        let (frame, step, iterations) = match found {
            Ok(f) => f,
            Err(why) => return Localization::NotLocalized(why.to_string()),
        };
        let quality = quality(&step, points.len(), hull_cut, iterations, mode);
        if let Some(why) = self.rejection(&quality) {
            return Localization::NotLocalized(why);
        }
        // Tracking: the solution turned like the prior (the twin is turned half round from it);
        // global: the goals' colours where the solutions put the goals, else the hint.
        let (chosen, other, by_goals) = match prior {
            Some(p) => {
                let (a, b) = frame.poses();
                let off = |q: &Isometry2<f64>| (q.rotation / p.rotation).angle().abs();
                if off(&a) <= off(&b) {
                    (a, b, false)
                } else {
                    (b, a, false)
                }
            }
            None => {
                let (a, b) = frame.poses();
                match self.sector_vote(img, &a) {
                    Some(true) => (a, b, true),
                    Some(false) => (b, a, true),
                    None => {
                        let nearer_b = hint.is_some_and(|h| {
                            let d = |q: &Isometry2<f64>| {
                                (q.translation.vector - h.translation.vector).norm()
                            };
                            d(&b) < d(&a)
                        });
                        if nearer_b {
                            (b, a, false)
                        } else {
                            (a, b, false)
                        }
                    }
                }
            }
        };
        Localization::Localized(PoseEstimate {
            pose: chosen,
            alternative: other,
            quality: LocalizationQuality {
                resolved_by_goals: by_goals,
                ..quality
            },
        })
    }

    /// Tracking: eq. (15) from the prior. When that fit fails the decision rule (near a corner
    /// a prior 150 mm off can pair the points with the wrong walls), the global first guesses
    /// and the prior are refined a little and the one explaining most points, among those near
    /// the prior, is finished instead.
    fn track_from(
        &self,
        points: &[BoundaryPoint],
        model: &Model,
        prior: &Isometry2<f64>,
        hull_cut: bool,
    ) -> Result<(FieldFrame, Step, usize), FitFailure> {
        let start = FieldFrame::of_pose(prior);
        let direct = self.refine(points, model, start, self.config.max_iterations);
        if let Some(found @ (_, step, iterations)) = &direct {
            let q = quality(
                step,
                points.len(),
                hull_cut,
                *iterations,
                LocalizationMode::Tracking,
            );
            if self.rejection(&q).is_none() {
                return Ok(found.clone());
            }
        }
        let near_prior = |f: &FieldFrame| {
            let turn = (f.psi - start.psi).rem_euclid(PI);
            (f.centre - start.centre).norm() < TRACKING_REACH_MM
                && turn.min(PI - turn) < TRACKING_REACH_RAD
        };
        let mut guesses = first_guesses(points, &self.config.field, None);
        guesses.push(start);
        let best = guesses
            .into_iter()
            .filter_map(|g| self.trial(points, model, g))
            .filter(|(f, _)| near_prior(f))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match best {
            Some((f, _)) => self
                .refine(points, model, f, self.config.max_iterations)
                .ok_or(FitFailure::NearPrior),
            None => direct.ok_or(FitFailure::FromPrior),
        }
    }

    /// Which of the two solutions the goals' colours support: `Some(true)` for `a`,
    /// `Some(false)` for its half-turn twin, `None` when neither goal colour is seen where the
    /// solutions put the goals.
    ///
    /// The twin puts the +x goal where `a` puts the -x goal and the other way round, so only
    /// two sectors of the image matter: `S1`, where `a` sees the +x goal, and `S2`, where it
    /// sees the -x goal. `a` predicts the +x colour in `S1` and the -x colour in `S2`, the twin
    /// the opposite; the colours counted there vote. (The paper's method counts goal colours
    /// over the whole image; looking only where the goals can be is cheaper, and another
    /// robot's blue or yellow marker elsewhere cannot sway it.)
    fn sector_vote(&self, img: &RgbaImage, a: &Isometry2<f64>) -> Option<bool> {
        let c = &self.config;
        let (s1, s2) = (
            self.goal_sector(a, 1.0)
                .map(|s| self.count_goal_colours(img, &s)),
            self.goal_sector(a, -1.0)
                .map(|s| self.count_goal_colours(img, &s)),
        );
        let [y1, b1] = s1.unwrap_or([0, 0]);
        let [y2, b2] = s2.unwrap_or([0, 0]);
        let (for_a, for_b) = (y1 + b2, b1 + y2);
        if for_a.max(for_b) < c.min_goal_pixels || for_a == for_b {
            return None;
        }
        Some(for_a > for_b)
    }

    /// Where, in the image, the goal at `side` (+1: +x, -1: -x) lies when the robot stands at
    /// `pose`: its azimuth range about the camera axis (from the goal box's corners, widened by
    /// three degrees) and the image radius of its nearest point on the floor.
    fn goal_sector(&self, pose: &Isometry2<f64>, side: f64) -> Option<GoalSector> {
        let f = &self.config.field;
        // The goal box: the pocket from the goal line back, with room for the walls.
        let (x0, x1, half) = (f.a1_mm, f.a2_mm + 60.0, f.goal_half_width_mm + 60.0);
        let [mx, my] = self.cal.mount_mm;
        let corners: Vec<Vector2<f64>> = [(x0, -half), (x0, half), (x1, -half), (x1, half)]
            .iter()
            .map(|&(x, y)| {
                let q = pose.inverse_transform_point(&Point2::new(side * x, y));
                Vector2::new(q.x - mx, q.y - my)
            })
            .collect();
        let mid = corners.iter().sum::<Vector2<f64>>() / 4.0;
        let centre = mid.y.atan2(mid.x);
        let offsets = corners
            .iter()
            .map(|q| Rotation2::new(q.y.atan2(q.x) - centre).angle());
        let (lo, hi) = offsets.fold((0.0f64, 0.0f64), |(lo, hi), o| (lo.min(o), hi.max(o)));
        let margin = 3f64.to_radians();
        // Inside the box (in the pocket) the goal is all around.
        let inside = {
            let q = pose * Point2::new(mx, my);
            (x0..=x1).contains(&(side * q.x)) && q.y.abs() <= half
        };
        let (from, to) = if inside {
            (-PI, PI)
        } else {
            (lo - margin, hi + margin)
        };
        let nearest = if inside {
            0.0
        } else {
            corners
                .iter()
                .map(|q| q.norm())
                .fold(f64::INFINITY, f64::min)
                .min(mid.norm())
        };
        let r_in = self
            .cal
            .image_radius_px(nearest)
            .unwrap_or(self.cal.samples.first()?[0])
            .max(self.cal.samples.first()?[0]);
        Some(GoalSector {
            from: centre + from,
            to: centre + to,
            r_in,
            r_out: self.cal.horizon_px * 1.1,
        })
    }

    /// Pixels of the +x and -x goal colours in a sector of the image, sampled every other
    /// pixel along and across the rays (each sample standing for four pixels).
    fn count_goal_colours(&self, img: &RgbaImage, s: &GoalSector) -> [usize; 2] {
        let c = &self.config;
        let [cx, cy] = self.cal.principal_point_px;
        let (w, h) = (img.width() as f64, img.height() as f64);
        let mut n = [0usize; 2];
        let mut r = s.r_in.max(1.0);
        while r <= s.r_out {
            let steps = ((s.to - s.from) * r / 2.0).ceil().max(1.0) as usize;
            // The ray's direction turned step by step (a rotation a sample), not recomputed.
            let (ds, dc) = ((s.to - s.from) / steps as f64).sin_cos();
            let (mut sin, mut cos) = s.from.sin_cos();
            for _ in 0..=steps {
                let (u, v) = ((cx + r * cos).floor(), (cy - r * sin).floor());
                (cos, sin) = (cos * dc - sin * ds, sin * dc + cos * ds);
                if u < 0.0 || v < 0.0 || u >= w || v >= h {
                    continue;
                }
                let p = img.get_pixel(u as u32, v as u32).0;
                let rgb = [p[0], p[1], p[2]];
                n[0] += 4 * c.goal_pos_x.contains(rgb) as usize;
                n[1] += 4 * c.goal_neg_x.contains(rgb) as usize;
            }
            r += 2.0;
        }
        n
    }

    /// The decision rule's reason to say "not localized", if any.
    fn rejection(&self, q: &LocalizationQuality) -> Option<String> {
        let c = &self.config;
        let (across_x, across_y) = (
            Model::count_across(&q.points_per_line, true),
            Model::count_across(&q.points_per_line, false),
        );
        if across_x < c.min_points_per_axis || across_y < c.min_points_per_axis {
            return Some(format!(
                "the boundary seen does not fix both axes ({across_x} points on goal lines or \
                 backs, {across_y} on touchlines or goal sides; need {} each)",
                c.min_points_per_axis
            ));
        }
        if q.inlier_fraction < c.min_inlier_fraction {
            return Some(format!(
                "the fitted field explains only {:.0}% of the boundary points (need {:.0}%)",
                100.0 * q.inlier_fraction,
                100.0 * c.min_inlier_fraction
            ));
        }
        if q.rms_residual_mm > c.max_rms_mm {
            return Some(format!(
                "fit residual {:.1} mm (at most {:.1})",
                q.rms_residual_mm, c.max_rms_mm
            ));
        }
        let [sx, sy, st] = q.sigma;
        if sx.max(sy) > c.max_sigma_mm || st.to_degrees() > c.max_sigma_deg {
            return Some(format!(
                "the boundary seen fixes the pose only to {sx:.0} mm, {sy:.0} mm and {:.1} deg \
                 (at most {} mm and {} deg)",
                st.to_degrees(),
                c.max_sigma_mm,
                c.max_sigma_deg
            ));
        }
        None
    }

    /// Boundary points where the outermost floor pixel of a row or column has a wall or a goal
    /// just beyond it, converted to the floor; and whether the floor ran on past the analysed
    /// image's edge somewhere.
    fn wall_points(&self, img: &RgbaImage) -> WallPoints {
        let (w, h) = (self.mask.width, self.mask.height);
        let r_max = self.config.max_radius_frac * self.cal.horizon_px;
        let [x0, y0, _, _] = self.region();
        // Mask pixel (u, v) is image pixel (u + x0, v + y0).
        let cx = self.cal.principal_point_px[0] - x0 as f64;
        let cy = self.cal.principal_point_px[1] - y0 as f64;
        let mut out = WallPoints {
            points: Vec::with_capacity(2 * (w + h)),
            cut: false,
            directions: Directions::default(),
        };
        // The last few points of each of the four traces (first and last floor pixel of the
        // rows, of the columns), by the row or column they came from.
        const BASE: usize = Directions::BASE;
        /// A point and the row or column it came from.
        type Traced = Option<(usize, Point2<f64>)>;
        let mut last: [[Traced; BASE]; 4] = [[None; BASE]; 4];
        // (eu, ev): the outer edge of the outermost floor pixel of a row or column, in
        // continuous mask coordinates; trace and row or column.
        let mut consider = |eu: f64, ev: f64, trace: usize, index: usize| {
            let (x, y) = (eu - cx, cy - ev);
            let big_r = x.hypot(y);
            if big_r > r_max {
                out.cut = true;
                return;
            }
            match self.beyond(img, x, y) {
                Beyond::Boundary => {}
                Beyond::Cut => {
                    out.cut = true;
                    return;
                }
                Beyond::Occluder => return,
            }
            // Eqs. (1)-(4): distance f(R) along the pixel's azimuth, and the weight of eq. (15).
            if let Some((r, slope)) = self.cal.floor_distance_and_slope(big_r) {
                let [mx, my] = self.cal.mount_mm;
                let p = Point2::new(mx + r * x / big_r, my + r * y / big_r);
                let slot = index % BASE;
                if let Some((k, q)) = last[trace][slot]
                    && k + BASE == index
                {
                    out.directions.add(p - q);
                }
                last[trace][slot] = Some((index, p));
                out.points.push(BoundaryPoint::new(p, slope));
            }
        };
        for v in 1..h.saturating_sub(1) {
            let row = &self.mask.data[v * w..(v + 1) * w];
            if let (Some(a), Some(b)) = (
                row.iter().position(|&m| m != 0),
                row.iter().rposition(|&m| m != 0),
            ) {
                consider(a as f64, v as f64 + 0.5, 0, v);
                consider(b as f64 + 1.0, v as f64 + 0.5, 1, v);
            }
        }
        let columns = self.mask.column_extents();
        for (u, extent) in columns.iter().enumerate().take(w.saturating_sub(1)).skip(1) {
            if let Some((a, b)) = *extent {
                consider(u as f64 + 0.5, a as f64, 2, u);
                consider(u as f64 + 0.5, b as f64 + 1.0, 3, u);
            }
        }
        out
    }

    /// Classifies what lies radially outward of the boundary point at image coordinates
    /// `(x, y)` (from the principal point, y up), 1.5 and 3 pixels on: the wall (or goal) a
    /// floor edge stands against rises outward along the ray, while where the floor meets a
    /// wall's face sideways (a wall so near that the body hides its foot) the ray runs on over
    /// floor.
    fn beyond(&self, img: &RgbaImage, x: f64, y: f64) -> Beyond {
        let c = &self.config;
        let r = x.hypot(y).max(1e-9);
        let [cx, cy] = self.cal.principal_point_px;
        let mut floor = false;
        for step in [1.5, 3.0] {
            let (px, py) = (x + x / r * step, y + y / r * step);
            let (u, v) = ((cx + px).floor(), (cy - py).floor());
            if u < 0.0 || v < 0.0 || u >= img.width() as f64 || v >= img.height() as f64 {
                return Beyond::Cut;
            }
            let p = img.get_pixel(u as u32, v as u32).0;
            let rgb = [p[0], p[1], p[2]];
            if c.wall.contains(rgb) || c.goal_pos_x.contains(rgb) || c.goal_neg_x.contains(rgb) {
                return Beyond::Boundary;
            }
            floor |= c.floor.contains(rgb);
        }
        if floor { Beyond::Cut } else { Beyond::Occluder }
    }

    /// Iterates eq. (15) from `frame` until the update is below its thresholds (or `max`
    /// iterations), the first two with the initial gate; the converged frame, its last step
    /// (with the final gate) and the iterations run.
    fn refine(
        &self,
        points: &[BoundaryPoint],
        model: &Model,
        frame: FieldFrame,
        max: usize,
    ) -> Option<(FieldFrame, Step, usize)> {
        self.refine_from(points, model, frame, max, 0)
    }

    /// [`Self::refine`] from a frame that has already had `settled` of its iterations (a
    /// trial's, at most two of them with the initial gate): those are not run again.
    fn refine_from(
        &self,
        points: &[BoundaryPoint],
        model: &Model,
        mut frame: FieldFrame,
        max: usize,
        settled: usize,
    ) -> Option<(FieldFrame, Step, usize)> {
        let c = &self.config;
        let mut last = None;
        for k in settled.min(2)..max.max(3) {
            let gate = if k < 2 { c.gate_initial_mm } else { c.gate_mm };
            let step = fit_step(points, model, &posts(&self.config.field), &frame, gate)?;
            let d = step.delta;
            frame.centre += Rotation2::new(frame.psi) * Vector2::new(d.x, d.y);
            frame.psi += d.z;
            let done = k >= 2
                && d.x.abs() < c.offset_threshold_mm
                && d.y.abs() < c.offset_threshold_mm
                && d.z.abs() < c.rotation_threshold_rad;
            last = Some((step, k + 1));
            if done {
                break;
            }
        }
        let (_, iterations) = last?;
        // The quality of the converged frame, at the final gate.
        let step = fit_step(points, model, &posts(&self.config.field), &frame, c.gate_mm)?;
        Some((frame, step, iterations))
    }

    /// A first guess refined by [`TRIAL_ITERATIONS`] of eq. (15), and the share of the points
    /// its last step explained (cheaper than [`Self::refine`]'s closing step, and as good for
    /// comparing guesses).
    fn trial(
        &self,
        points: &[BoundaryPoint],
        model: &Model,
        mut frame: FieldFrame,
    ) -> Option<(FieldFrame, f64)> {
        let c = &self.config;
        let posts = posts(&c.field);
        let mut explained = 0.0;
        for k in 0..TRIAL_ITERATIONS {
            let gate = if k < 2 { c.gate_initial_mm } else { c.gate_mm };
            let step = fit_step(points, model, &posts, &frame, gate)?;
            let d = step.delta;
            frame.centre += Rotation2::new(frame.psi) * Vector2::new(d.x, d.y);
            frame.psi += d.z;
            explained = step.explained;
        }
        Some((frame, explained))
    }

    /// Global mode: refines every first guess a little, keeps the one that explains most
    /// boundary points, finishes it, and refuses when another, different pose explains nearly
    /// as many.
    fn search(
        &self,
        points: &[BoundaryPoint],
        model: &Model,
        rough_direction: Option<f64>,
    ) -> Result<(FieldFrame, Step, usize), FitFailure> {
        // The trials run on every fourth point: enough to tell the guesses apart. Each guess is
        // scored by what its first step explains on every sixth, and the best few are refined
        // further.
        let sample: Vec<BoundaryPoint> = points.iter().step_by(4).copied().collect();
        let sparse: Vec<BoundaryPoint> = points.iter().step_by(6).copied().collect();
        let posts = posts(&self.config.field);
        let mut guesses: Vec<(FieldFrame, f64)> =
            first_guesses(points, &self.config.field, rough_direction)
                .into_iter()
                .filter_map(|g| {
                    fit_step(&sparse, model, &posts, &g, self.config.gate_initial_mm)
                        .map(|s| (g, s.explained))
                })
                .collect();
        guesses.sort_by(|a, b| b.1.total_cmp(&a.1));
        let mut trials: Vec<(FieldFrame, f64)> = guesses
            .into_iter()
            .take(TRIALS)
            .filter_map(|(g, _)| self.trial(&sample, model, g))
            .collect();
        trials.sort_by(|a, b| b.1.total_cmp(&a.1));
        let best_trial = trials.first().map_or(0.0, |t| t.1);
        let Some(&(best, _)) = trials.first() else {
            return Err(FitFailure::NoGuess);
        };
        let (frame, step, iterations) = self
            .refine_from(
                points,
                model,
                best,
                self.config.max_iterations,
                TRIAL_ITERATIONS,
            )
            .ok_or(FitFailure::BestGuess)?;
        // Rivals: the other trials that came near the best, finished too.
        let rival = trials
            .iter()
            .filter(|(f, e)| !same_field(f, &frame) && *e >= AMBIGUOUS_SHARE * best_trial - 0.05)
            .filter_map(|(f, _)| {
                let max = self.config.max_iterations;
                self.refine_from(points, model, *f, max, TRIAL_ITERATIONS)
            })
            .find(|(f, s, _)| {
                !same_field(f, &frame) && s.explained >= AMBIGUOUS_SHARE * step.explained
            });
        if let Some((other, s, _)) = rival {
            let (a, _) = other.poses();
            return Err(FitFailure::Ambiguous {
                x_mm: a.translation.x,
                y_mm: a.translation.y,
                heading_deg: a.rotation.angle().to_degrees(),
                rival_percent: 100.0 * s.explained,
                best_percent: 100.0 * step.explained,
            });
        }
        Ok((frame, step, iterations))
    }
}

/// A boundary point seen this close past a goal post (its line of sight grazing the post)
/// may be the post's silhouette against the floor behind it, not the floor's edge, mm.
const POST_SHADOW_MM: f64 = 40.0;

/// Whether `p` lies behind `post` (both from the robot) with its line of sight passing within
/// [`POST_SHADOW_MM`] of the post.
fn past_post(p: Vector2<f64>, post: Vector2<f64>) -> bool {
    // Along the sight line: 0 < post . p < |p|^2; across it: |p x post| / |p| < the shadow.
    let (along, len2) = (post.dot(&p), p.norm_squared());
    let across = p.perp(&post);
    along > 0.0 && along < len2 && across * across < POST_SHADOW_MM * POST_SHADOW_MM * len2
}

/// The goal posts: where the goal lines meet the goal pockets' side walls, the only corners of
/// the floor's outline that hide floor behind them; those at +x first.
fn posts(f: &FieldModel) -> [Vector2<f64>; 4] {
    let (a, g) = (f.a1_mm, f.goal_half_width_mm);
    [
        Vector2::new(a, g),
        Vector2::new(a, -g),
        Vector2::new(-a, g),
        Vector2::new(-a, -g),
    ]
}

/// The quality record of a fit.
fn quality(
    step: &Step,
    boundary_points: usize,
    hull_cut: bool,
    iterations: usize,
    mode: LocalizationMode,
) -> LocalizationQuality {
    LocalizationQuality {
        rms_residual_mm: step.rms_mm,
        points: step.used,
        lines: step.per_segment.iter().filter(|&&n| n > 0).count(),
        points_per_line: step.per_segment.to_vec(),
        boundary_points,
        inlier_fraction: step.explained,
        sigma: step.sigma,
        hull_cut,
        iterations,
        mode,
        resolved_by_goals: false,
    }
}

/// Whether two field frames are the same field, up to the half-turn twin.
fn same_field(a: &FieldFrame, b: &FieldFrame) -> bool {
    let turn = (a.psi - b.psi).rem_euclid(PI);
    (a.centre - b.centre).norm() < SAME_MM && turn.min(PI - turn) < SAME_RAD
}

/// The field model: twelve segments of the floor region's outline in the field frame, the
/// paper's six lines of Fig. 6 with their extents (goal backs within the goal mouths, goal lines
/// beside them, touchlines) and the side walls of the two goal pockets, which the paper's model
/// leaves out (points on them were taken for the goal lines or backs). The goal lines and
/// touchlines stand the painted boundary line's width inside the walls, where the floor colour
/// ends. Segment `k` of side `s` (`+x`: 0-5, `-x`: 6-11): goal back, goal line at `y > 0`, goal
/// line at `y < 0`, pocket side `y = g`, pocket side `y = -g`, and the touchline `y = +B` (for
/// `+x`) or `y = -B` (for `-x`).
#[derive(Debug, Clone, Copy)]
struct Model {
    /// Goal lines, x = +-a1l.
    a1l: f64,
    /// Goal backs, x = +-a2.
    a2: f64,
    /// Touchlines, y = +-bl.
    bl: f64,
    /// Pocket sides, y = +-g.
    g: f64,
}

impl Model {
    const SEGMENTS: usize = 12;

    fn new(f: &FieldModel) -> Self {
        Self {
            a1l: f.a1_mm - f.boundary_line_mm,
            a2: f.a2_mm,
            bl: f.b_mm - f.boundary_line_mm,
            g: f.goal_half_width_mm,
        }
    }

    /// The outward normal of segment `k`.
    fn normal(k: usize) -> Vector2<f64> {
        let sx = if k < 6 { 1.0 } else { -1.0 };
        match k % 6 {
            0..=2 => Vector2::new(sx, 0.0),
            3 => Vector2::y(),
            4 => -Vector2::y(),
            _ => Vector2::new(0.0, sx),
        }
    }

    /// Whether segment `k` runs across the field's x axis (fixes x), else across y.
    fn across_x(k: usize) -> bool {
        k % 6 <= 2
    }

    /// The nearest segment whose extent (widened by half the gate) holds `q` and whose line
    /// lies within the gate, or within [`GATE_PIXELS`] of the point's pixel when that is
    /// coarser (a pixel spans `pixel_mm` there): index and signed distance `n . q - c`. The
    /// field's symmetry leaves only the segments on the point's side of each axis to try.
    fn assign(&self, q: Vector2<f64>, gate: f64, pixel_mm: f64) -> Option<(usize, f64)> {
        let ends = 0.5 * gate;
        let gate = gate.max(GATE_PIXELS * pixel_mm);
        let (ax, ay) = (q.x.abs(), q.y.abs());
        let base = if q.x >= 0.0 { 0 } else { 6 };
        let upper = q.y >= 0.0;
        let mut best: Option<(usize, f64)> = None;
        let mut consider = |k: usize, d0: f64| {
            if d0.abs() <= gate && best.is_none_or(|b| d0.abs() < b.1.abs()) {
                best = Some((k, d0));
            }
        };
        if ay <= self.g + ends {
            consider(base, ax - self.a2);
        }
        if ay >= self.g - ends && ay <= self.bl + ends {
            consider(base + if upper { 1 } else { 2 }, ax - self.a1l);
        }
        if ax >= self.a1l - ends && ax <= self.a2 + ends {
            consider(base + if upper { 3 } else { 4 }, ay - self.g);
        }
        if ax <= self.a1l + ends {
            consider(if upper { 5 } else { 11 }, ay - self.bl);
        }
        best
    }

    /// Points on segments across the x axis (`true`) or the y axis.
    fn count_across(per_segment: &[usize], x: bool) -> usize {
        per_segment
            .iter()
            .enumerate()
            .filter(|(k, _)| Self::across_x(*k) == x)
            .map(|(_, n)| n)
            .sum()
    }
}

/// One step of eq. (15): each point (in the field frame of eqs. (13)-(14)) not seen past a goal
/// post is assigned to a segment ([`Model::assign`]); the residual `n . q - c` is linearised in
/// the field's offset (u, v) and small rotation zeta, `J = (-n_x, -n_y, n_x q_y - n_y q_x)`, and
/// the weighted least squares solved. `None` when the assigned points do not fix both axes.
fn fit_step(
    points: &[BoundaryPoint],
    model: &Model,
    posts: &[Vector2<f64>; 4],
    frame: &FieldFrame,
    gate: f64,
) -> Option<Step> {
    let (s, c) = frame.psi.sin_cos();
    // Eqs. (13)-(14): robot-frame point to field frame.
    let to_field = |p: Point2<f64>| {
        let d = p - frame.centre;
        Vector2::new(d.x * c + d.y * s, -d.x * s + d.y * c)
    };
    // The robot in the field frame. Seen from between the goal lines, a point can lie behind a
    // post only beyond the goal line less the shadow's width; from elsewhere, anywhere.
    let robot = to_field(Point2::origin());
    let shadow_x = posts[0].x.abs() - POST_SHADOW_MM;
    let inside = robot.x.abs() <= shadow_x;
    // The posts a point may lie behind: none, those on its side of the field (seen from
    // between the goal lines), or all.
    let candidates = |q: &Vector2<f64>| -> &[Vector2<f64>] {
        match (inside, q.x.abs() > shadow_x, q.x > 0.0) {
            (false, _, _) => &posts[..],
            (true, false, _) => &[],
            (true, true, true) => &posts[..2],
            (true, true, false) => &posts[2..],
        }
    };
    let mut ata = Matrix3::<f64>::zeros();
    let mut atb = Vector3::<f64>::zeros();
    let mut per_segment = [0usize; Model::SEGMENTS];
    let (mut sum_w, mut sum_wd2) = (0.0, 0.0);
    let mut seen = 0usize;
    for bp in points {
        let q = to_field(bp.p);
        if candidates(&q)
            .iter()
            .any(|post| past_post(q - robot, post - robot))
        {
            continue;
        }
        seen += 1;
        let best = model.assign(q, gate, bp.pixel_mm);
        let Some((k, d0)) = best else { continue };
        let n = Model::normal(k);
        let j = Vector3::new(-n.x, -n.y, n.x * q.y - n.y * q.x);
        per_segment[k] += 1;
        ata += j * j.transpose() * bp.w;
        atb -= j * (d0 * bp.w);
        sum_w += bp.w;
        sum_wd2 += bp.w * d0 * d0;
    }
    let used: usize = per_segment.iter().sum();
    let across = |x: bool| Model::count_across(&per_segment, x);
    if across(true) < 3 || across(false) < 3 || used < 10 {
        return None;
    }
    let inverse = ata.try_inverse()?;
    let delta = inverse * atb;
    // The residual variance (in the weights' units, image pixels squared) times the inverse
    // normal matrix.
    let variance = sum_wd2 / (used - 3) as f64;
    let sigma = [0, 1, 2].map(|i| (variance * inverse[(i, i)]).max(0.0).sqrt());
    Some(Step {
        delta,
        rms_mm: (sum_wd2 / sum_w).sqrt(),
        used,
        per_segment,
        explained: used as f64 / seen.max(1) as f64,
        sigma,
    })
}

/// Global first guesses: the field's orientation from the directions of the boundary, then,
/// for each of its two axes as the field's x axis, offsets that put the outermost walls seen on
/// the model's walls.
fn first_guesses(
    points: &[BoundaryPoint],
    f: &FieldModel,
    rough_direction: Option<f64>,
) -> Vec<FieldFrame> {
    let theta = dominant_orientation(points, rough_direction);
    let (x_walls, y_wall) = (
        [f.a1_mm - f.boundary_line_mm, f.a2_mm],
        f.b_mm - f.boundary_line_mm,
    );
    let mut out: Vec<FieldFrame> = Vec::new();
    for psi in [theta, theta + FRAC_PI_2] {
        let (u, v) = (
            Vector2::new(psi.cos(), psi.sin()),
            Vector2::new(-psi.sin(), psi.cos()),
        );
        let (x_lo, x_hi) = outer_walls(points.iter().map(|b| b.p.coords.dot(&u)).collect());
        let (y_lo, y_hi) = outer_walls(points.iter().map(|b| b.p.coords.dot(&v)).collect());
        let ox: Vec<f64> = x_walls
            .iter()
            .flat_map(|&wx| [x_hi - wx, x_lo + wx])
            .collect();
        let mut oy = vec![y_hi - y_wall, y_lo + y_wall];
        oy.push(0.5 * (y_hi + y_lo));
        for &x in &ox {
            for &y in &oy {
                let frame = FieldFrame {
                    centre: Point2::from(u * x + v * y),
                    psi,
                };
                if !out.iter().any(|o| same_field(o, &frame)) {
                    out.push(frame);
                }
            }
        }
    }
    out
}

/// The outermost coordinates on either side (least, greatest) backed by at least four points
/// within 40 mm: walls, not stray points.
fn outer_walls(mut values: Vec<f64>) -> (f64, f64) {
    const BACKING: usize = 4;
    let backed = |w: &[f64]| (w[BACKING - 1] - w[0]).abs() <= 40.0;
    // Mostly the outermost few points are backed: sort only the 16 least and greatest (all
    // when there are few), and the rest only when those hold no wall.
    let n = values.len();
    let k = 16.min(n);
    let lo = {
        if k < n {
            values.select_nth_unstable_by(k, f64::total_cmp);
        }
        values[..k].sort_unstable_by(f64::total_cmp);
        values[..k]
            .windows(BACKING)
            .find(|w| backed(w))
            .map(|w| w[0])
    };
    let hi = {
        if k < n {
            values.select_nth_unstable_by(n - k - 1, f64::total_cmp);
        }
        values[n - k..].sort_unstable_by(f64::total_cmp);
        values[n - k..]
            .windows(BACKING)
            .rev()
            .find(|w| backed(w))
            .map(|w| w[BACKING - 1])
    };
    if let (Some(lo), Some(hi)) = (lo, hi) {
        return (lo, hi);
    }
    values.sort_unstable_by(f64::total_cmp);
    let lo = values.windows(BACKING).find(|w| backed(w)).map(|w| w[0]);
    let hi = values
        .windows(BACKING)
        .rev()
        .find(|w| backed(w))
        .map(|w| w[BACKING - 1]);
    (
        lo.or(values.first().copied()).unwrap_or(0.0),
        hi.or(values.last().copied()).unwrap_or(0.0),
    )
}

/// The rotation in [0, pi/2) at which the boundary points' coordinates along both axes are
/// most concentrated (the sum of the squared counts of 25 mm bins): walls meet at right angles,
/// so their points pile up in few bins when the axes run along them.
fn dominant_orientation(points: &[BoundaryPoint], rough: Option<f64>) -> f64 {
    const BIN_MM: f64 = 25.0;
    // Every other point is plenty to find the walls' direction; every fourth for the coarse
    // steps.
    let sample: Vec<Point2<f64>> = points.iter().step_by(2).map(|b| b.p).collect();
    let reach = sample.iter().map(|p| p.coords.norm()).fold(0.0, f64::max);
    let half = (reach / BIN_MM).ceil() as usize + 1;
    let mut bins = vec![0f64; 2 * half + 1];
    let mut keys = vec![0usize; sample.len()];
    // Each point is shared between its two nearest bins in proportion (so that the score
    // changes smoothly with the rotation, not in steps as points cross bin edges).
    let mut score = |theta: f64, stride: usize| -> f64 {
        let (s, c) = theta.sin_cos();
        let mut total = 0.0;
        for axis in [(c, s), (-s, c)] {
            // The sum of squared counts, kept as the bins fill: (n + a)^2 - n^2 = (2 n + a) a.
            for (key, p) in keys.iter_mut().zip(sample.iter().step_by(stride)) {
                let x = (p.x * axis.0 + p.y * axis.1) / BIN_MM + half as f64;
                let k = (x.max(0.0) as usize).min(2 * half - 1);
                let b = (x - k as f64).clamp(0.0, 1.0);
                let a = 1.0 - b;
                total += (2.0 * bins[k] + a) * a + (2.0 * bins[k + 1] + b) * b;
                bins[k] += a;
                bins[k + 1] += b;
                *key = k;
            }
            for &k in keys.iter().take(sample.len().div_ceil(stride)) {
                bins[k] = 0.0;
                bins[k + 1] = 0.0;
            }
        }
        total
    };
    // From the rough direction of the boundary's steps when they agree on one, else the best
    // of every five degrees; then one degree, then a fifth, each searching the span the step
    // before leaves open.
    let mut best_of = |angles: Vec<f64>, stride: usize| {
        angles
            .into_iter()
            .map(|t| (t, score(t, stride)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(t, _)| t)
    };
    let mut best = match rough {
        Some(r) => r,
        None => {
            let coarse = (0..18).map(|k| (5.0 * k as f64).to_radians()).collect();
            best_of(coarse, 2).unwrap_or(0.0)
        }
    };
    for (step, stride) in [(1.0f64, 2), (0.2, 1)] {
        let around = (-3..=3)
            .map(|k| best + (step * k as f64).to_radians())
            .collect();
        best = best_of(around, stride).unwrap_or(best);
    }
    best.rem_euclid(FRAC_PI_2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_field_in_the_frame_of_a_pose_gives_that_pose_back() {
        let pose = Isometry2::new(Vector2::new(-700.0, 320.0), 2.1);
        let (a, b) = FieldFrame::of_pose(&pose).poses();
        assert!((a.translation.vector - pose.translation.vector).norm() < 1e-9);
        assert!((a.rotation.angle() - pose.rotation.angle()).abs() < 1e-12);
        assert!((b.translation.vector + pose.translation.vector).norm() < 1e-9);
    }

    #[test]
    fn points_on_each_wall_go_to_its_segment() {
        let f = FieldModel::default();
        let m = Model::new(&f);
        let (a1l, bl) = (f.a1_mm - 10.0, f.b_mm - 10.0);
        // (point a little inside the floor, expected segment)
        let cases = [
            ((1545.0, 100.0), 0),
            ((a1l - 5.0, 500.0), 1),
            ((a1l - 5.0, -500.0), 2),
            ((1450.0, 245.0), 3),
            ((1450.0, -245.0), 4),
            ((0.0, bl - 5.0), 5),
            ((-1545.0, -100.0), 6),
            ((-a1l + 5.0, 500.0), 7),
            ((-1450.0, -245.0), 10),
            ((0.0, -bl + 5.0), 11),
        ];
        for ((x, y), k) in cases {
            let (got, d0) = m.assign(Vector2::new(x, y), 60.0, 1.0).unwrap();
            assert_eq!(got, k, "({x}, {y})");
            assert!((d0 + 5.0).abs() < 1e-9, "({x}, {y}): {d0}");
        }
        // The middle of the field is near no wall.
        assert!(m.assign(Vector2::new(0.0, 0.0), 60.0, 1.0).is_none());
        let across_x = (0..Model::SEGMENTS).filter(|&k| Model::across_x(k)).count();
        assert_eq!(across_x, 6);
    }

    #[test]
    fn the_orientation_of_a_truncated_corner_is_found() {
        // A corner's two walls, seen from inside, turned by 0.3 rad: points on two
        // perpendicular lines only.
        let r = Rotation2::new(0.3);
        let mut pts = Vec::new();
        for k in 0..60 {
            let s = k as f64 * 20.0;
            for p in [Point2::new(400.0, s - 300.0), Point2::new(s - 500.0, 700.0)] {
                pts.push(BoundaryPoint::new(Point2::from(r * p.coords), 1.0));
            }
        }
        let theta = dominant_orientation(&pts, None);
        assert!((theta - 0.3).abs() < 0.01, "{theta}");
    }
}
