//! Self-localization from the shape of the floor region (Sect. 4 of the corner paper), as the
//! paper publishes it and made to hold anywhere on the field.
//!
//! The paper's method ([`LocalizationMethod::Paper`], module `paper`):
//! 1. Extract the floor by colour and clean it with dilation/erosion.
//! 2. Boundary points: the outermost floor pixels of every image row (`X_min`, `X_max`) and, so
//!    that the near-horizontal parts of the boundary are sampled too, of every column.
//! 3. (with 4.) Convert the points to the floor through `f(R)` (eqs. (1)-(4)) and take their
//!    convex hull there. The hull restores the parts of the boundary hidden by obstacles; it is
//!    taken on the floor rather than in the image because the mirror bows straight floor lines
//!    toward the image centre, so the floor region is not convex in the image.
//! 5. Area moments of the hull by triangles (eq. (9)), centre of gravity (eq. (10)) and the long
//!    principal axis (eqs. (11)-(12)): a first estimate of where the field centre and axis are.
//! 6. In the frame of that estimate (eqs. (13)-(14)) each boundary point is assigned to the
//!    nearest of the six lines of Fig. 6 (goal backs x = +-A2 within the goal mouth, goal lines
//!    x = +-A1 beside it, touchlines y = +-B) when it is near enough, and eq. (15),
//!    `J = sum w_i d_i^2` with `w_i = 1 / (df/dR(R_i))^2`, is minimised over the offset and
//!    rotation of the field, linearised for small rotation; the estimate is updated (eqs.
//!    (16)-(18)) and the step repeated until the update is below its thresholds.
//! 7. The robot's pose in the field frame (eqs. (19)-(21)) has two solutions a half turn apart;
//!    the blue and yellow goals seen in the image choose between them.
//!
//! Near a wall the robot's own body hides the floor up to the wall, so the outermost floor
//! pixels of many rows are the edge of the body's shadow, not the field's boundary; near a
//! corner the moments of what is left are a poor first guess, and the fit settles on a wrong
//! pose it reports with confidence. Ours ([`LocalizationMethod::Robust`], module `robust`)
//! keeps eq. (15) and its weights, and changes what goes in and what comes out:
//! - a boundary point is kept only where the floor meets a wall or a goal (the colour just
//!   beyond the outermost floor pixel), never where it meets an obstacle (a cube, a robot, the
//!   robot's own body: their silhouettes) or the edge of the analysed image (the useful radius);
//! - the field model has twelve segments, the paper's six lines with their extents and the goal
//!   pockets' side walls, and the floor colour ends inside the painted boundary line;
//! - the first guess is, in tracking mode, the prior pose from the robot's estimator, and in
//!   global mode the best of several: the field's orientation from the directions of the
//!   boundary (the rotation that makes the boundary points' coordinates most concentrated) and
//!   offsets that put a wall the robot sees on each wall of the model, each refined by eq. (15)
//!   and the one that explains most boundary points kept;
//! - every estimate carries its quality ([`LocalizationQuality`]), and a decision rule turns a
//!   pose the boundary cannot support into "not localized" with the reason (see
//!   [`FloorLocalizer::track`]).

mod paper;
mod robust;

use crate::VisionError;
use crate::calibration::RadialCalibration;
use crate::mask::{FloorColor, Mask};
use image::RgbaImage;
use nalgebra::{Isometry2, Point2, Rotation2};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The floor region's outline (Fig. 6 of the corner paper).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FieldModel {
    /// A1: field centre to goal line.
    pub a1_mm: f64,
    /// A2: field centre to goal back.
    pub a2_mm: f64,
    /// B: field centre to touchline.
    pub b_mm: f64,
    /// Half the width of the goal mouth.
    pub goal_half_width_mm: f64,
    /// Width of the white line painted along the boundary inside the field: the floor colour
    /// ends this far inside the goal lines and touchlines (robust method; the paper's model has
    /// none).
    pub boundary_line_mm: f64,
}

impl Default for FieldModel {
    fn default() -> Self {
        Self {
            a1_mm: 1370.0,
            a2_mm: 1550.0,
            b_mm: 762.5,
            goal_half_width_mm: 250.0,
            boundary_line_mm: 10.0,
        }
    }
}

/// A colour class by chromaticity: `r = R / (R + G + B)` and `g = G / (R + G + B)` within their
/// ranges, and `R + G + B` at least `min_sum` (so dark, noisy pixels are left out). Shading
/// changes brightness, not chromaticity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColorClass {
    /// Range of `R / (R + G + B)`.
    pub r: [f64; 2],
    /// Range of `G / (R + G + B)`.
    pub g: [f64; 2],
    /// Smallest `R + G + B`.
    pub min_sum: u32,
}

impl ColorClass {
    /// Whether a pixel belongs to the class.
    pub fn contains(&self, p: [u8; 3]) -> bool {
        let s = p[0] as u32 + p[1] as u32 + p[2] as u32;
        // r in [r0, r1] <=> r0 s <= R <= r1 s (no division); `&`, not `&&`: no branches in
        // the per-pixel loops.
        let (rr, gg, ss) = (p[0] as f64, p[1] as f64, s as f64);
        (s >= self.min_sum.max(1))
            & (rr >= self.r[0] * ss)
            & (rr <= self.r[1] * ss)
            & (gg >= self.g[0] * ss)
            & (gg <= self.g[1] * ss)
    }
}

/// Which localization method runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum LocalizationMethod {
    /// Steps 1-7 of Sect. 4 as published: every outermost floor pixel, the six lines, the
    /// moments as first guess, no decision rule beyond the steps' own.
    Paper,
    /// This project's: boundary points only where the floor meets a wall or a goal, twelve
    /// segments, a tracking mode and a global search, and a decision rule.
    #[default]
    Robust,
}

/// Settings of the self-localization (`[vision.localization]` in scenarios).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LocalizationConfig {
    /// The method.
    pub method: LocalizationMethod,
    /// Floor colour.
    pub floor: FloorColor,
    /// Dilation/erosion passes cleaning the floor mask.
    pub morphology_iterations: u32,
    /// The field's outline.
    pub field: FieldModel,
    /// Colour of the goal at +x (yellow).
    pub goal_pos_x: ColorClass,
    /// Colour of the goal at -x (blue).
    pub goal_neg_x: ColorClass,
    /// Fewest pixels of a goal colour that count as seeing that goal.
    pub min_goal_pixels: usize,
    /// Boundary points beyond this fraction of the horizon radius are left out.
    pub max_radius_frac: f64,
    /// Fewest floor pixels for an attempt.
    pub min_floor_pixels: usize,
    /// A point joins a line when it is this close to it, in the first two iterations.
    pub gate_initial_mm: f64,
    /// ... and this close afterwards.
    pub gate_mm: f64,
    /// Iterations of eqs. (15)-(18) at most.
    pub max_iterations: usize,
    /// Stop when the offset update is below this (a_th, b_th).
    pub offset_threshold_mm: f64,
    /// Stop when the rotation update is below this (zeta_th).
    pub rotation_threshold_rad: f64,
    /// Robust method: colour of the walls (a boundary point needs a wall or goal colour just
    /// beyond the floor).
    pub wall: ColorClass,
    /// Robust method, decision rule: the fit's standard deviation of the position (from the
    /// least squares, along each field axis) must not exceed this, mm.
    pub max_sigma_mm: f64,
    /// ... and of the heading, degrees.
    pub max_sigma_deg: f64,
    /// ... the share of the boundary points the fitted field explains (within `gate_mm`, or
    /// two of a far point's pixels) must reach this.
    pub min_inlier_fraction: f64,
    /// ... the fit's weighted RMS residual must not exceed this, mm.
    pub max_rms_mm: f64,
    /// ... each field axis needs at least this many boundary points on segments across it.
    pub min_points_per_axis: usize,
}

impl Default for LocalizationConfig {
    fn default() -> Self {
        Self {
            floor: FloorColor::default(),
            morphology_iterations: 1,
            field: FieldModel::default(),
            goal_pos_x: ColorClass {
                r: [0.45, 0.65],
                g: [0.34, 0.50],
                min_sum: 120,
            },
            goal_neg_x: ColorClass {
                r: [0.0, 0.22],
                g: [0.08, 0.32],
                min_sum: 90,
            },
            min_goal_pixels: 8,
            max_radius_frac: 0.95,
            min_floor_pixels: 2000,
            gate_initial_mm: 200.0,
            gate_mm: 60.0,
            max_iterations: 30,
            offset_threshold_mm: 0.05,
            rotation_threshold_rad: 1e-5,
            method: LocalizationMethod::Robust,
            wall: ColorClass {
                r: [0.28, 0.40],
                g: [0.28, 0.40],
                min_sum: 300,
            },
            max_sigma_mm: 20.0,
            max_sigma_deg: 1.0,
            min_inlier_fraction: 0.6,
            max_rms_mm: 25.0,
            min_points_per_axis: 8,
        }
    }
}

/// How a pose estimate was made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LocalizationMode {
    /// From the image alone.
    Global,
    /// From a prior pose, the estimator's.
    Tracking,
}

/// How good a pose estimate is.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalizationQuality {
    /// Weighted RMS distance of the used boundary points to their lines, mm.
    pub rms_residual_mm: f64,
    /// Boundary points used in the final fit.
    pub points: usize,
    /// How many of the model's lines (segments) had points.
    pub lines: usize,
    /// Boundary points used on each of the model's segments (robust method; empty for the
    /// paper's).
    pub points_per_line: Vec<usize>,
    /// Boundary points found (after leaving out silhouettes and the image's edge).
    pub boundary_points: usize,
    /// Share of them the fitted field explains (robust method: leaving out those seen past a
    /// goal post).
    pub inlier_fraction: f64,
    /// Standard deviations of the position along the field's x and y axes (mm) and of the
    /// heading (rad), from the least squares (robust method; NaN for the paper's).
    pub sigma: [f64; 3],
    /// Whether the floor ran on past the analysed image's edge somewhere (the region seen is
    /// cut there, not bounded by the field).
    pub hull_cut: bool,
    /// Iterations of eqs. (15)-(18).
    pub iterations: usize,
    /// Global or tracking.
    pub mode: LocalizationMode,
    /// Whether the goal colours decided between the two solutions (otherwise the prior did, or
    /// nothing did).
    pub resolved_by_goals: bool,
}

/// A pose of the robot in the field frame.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseEstimate {
    /// The chosen solution.
    pub pose: Isometry2<f64>,
    /// The other solution of eq. (19), a half turn about the field centre away.
    pub alternative: Isometry2<f64>,
    /// Quality figures.
    pub quality: LocalizationQuality,
}

/// The outcome of one attempt.
#[derive(Debug, Clone, PartialEq)]
pub enum Localization {
    /// A pose.
    Localized(PoseEstimate),
    /// No pose, and why.
    NotLocalized(String),
}

impl Localization {
    /// The estimate, if any.
    pub fn estimate(&self) -> Option<&PoseEstimate> {
        match self {
            Localization::Localized(e) => Some(e),
            Localization::NotLocalized(_) => None,
        }
    }
}

/// A boundary point on the floor with its fit weight.
#[derive(Debug, Clone, Copy)]
struct BoundaryPoint {
    p: Point2<f64>,
    /// Eq. (15)'s weight `1 / (df/dR)^2`.
    w: f64,
    /// `df/dR`: the floor distance one image pixel spans there, mm.
    pixel_mm: f64,
}

impl BoundaryPoint {
    /// A point at `p` where one image pixel spans `slope_mm_per_px` of floor.
    fn new(p: Point2<f64>, slope_mm_per_px: f64) -> Self {
        Self {
            p,
            w: 1.0 / (slope_mm_per_px * slope_mm_per_px).max(1e-9),
            pixel_mm: slope_mm_per_px.abs(),
        }
    }
}

/// The field's frame in the robot's: where its centre is and where its x axis points.
#[derive(Debug, Clone, Copy, PartialEq)]
struct FieldFrame {
    centre: Point2<f64>,
    psi: f64,
}

impl FieldFrame {
    /// The frame of a robot pose in the field (the first of eq. (19)'s two solutions).
    fn of_pose(pose: &Isometry2<f64>) -> Self {
        // pose_for below inverted: t = -R(theta) g, theta = -psi.
        let theta = pose.rotation.angle();
        Self {
            centre: Point2::from(-(Rotation2::new(-theta) * pose.translation.vector)),
            psi: -theta,
        }
    }

    /// Step 7: the robot in the field frame. The field's x axis is at psi in the robot frame,
    /// so the robot's heading in the field is -psi, and its position is the field centre's
    /// position seen from the field: -R(theta) g (eqs. (19)-(21)); the other solution turns the
    /// field a half turn. (The rotation takes theta modulo 2 pi; its angle() reads back in
    /// (-pi, pi].)
    fn poses(&self) -> (Isometry2<f64>, Isometry2<f64>) {
        let pose_for = |theta: f64| {
            let t = -(Rotation2::new(theta) * self.centre.coords);
            Isometry2::new(t, theta)
        };
        (pose_for(-self.psi), pose_for(-self.psi + PI))
    }
}

/// Localizes a robot from images of one calibrated sensor.
#[derive(Debug, Clone)]
pub struct FloorLocalizer {
    config: LocalizationConfig,
    cal: RadialCalibration,
    mask: Mask,
    scratch: Vec<u8>,
}

impl FloorLocalizer {
    /// A localizer for images of the sensor `cal` describes.
    pub fn new(config: LocalizationConfig, cal: &RadialCalibration) -> Result<Self, VisionError> {
        cal.validate()?;
        let f = &config.field;
        if !(f.a1_mm > 0.0
            && f.a2_mm > f.a1_mm
            && f.b_mm > f.goal_half_width_mm
            && f.goal_half_width_mm > 0.0)
        {
            return Err(VisionError::InvalidParameter {
                name: "field (a1_mm, a2_mm, b_mm, goal_half_width_mm)",
                value: f.a1_mm,
                rule: "need 0 < a1 < a2 and 0 < goal_half_width < b",
            });
        }
        if !(config.max_radius_frac > 0.0 && config.max_radius_frac <= 1.0) {
            return Err(VisionError::InvalidParameter {
                name: "max_radius_frac",
                value: config.max_radius_frac,
                rule: "must lie in (0, 1]",
            });
        }
        Ok(Self {
            config,
            cal: cal.clone(),
            mask: Mask::new(0, 0),
            scratch: Vec::new(),
        })
    }

    /// The settings.
    pub fn config(&self) -> &LocalizationConfig {
        &self.config
    }

    /// Global mode: localizes from one image alone. `hint`, a pose in the field frame (e.g.
    /// dead reckoning), when given, chooses between the two solutions when no goal is seen.
    pub fn locate(
        &mut self,
        img: &RgbaImage,
        hint: Option<&Isometry2<f64>>,
    ) -> Result<Localization, VisionError> {
        if let Some(why) = self.prepare(img)? {
            return Ok(Localization::NotLocalized(why));
        }
        Ok(match self.config.method {
            LocalizationMethod::Paper => self.locate_paper(img, hint),
            LocalizationMethod::Robust => self.locate_robust(img, None, hint),
        })
    }

    /// Tracking mode: localizes from one image starting from `prior`, the estimator's pose in
    /// the field frame, which replaces the moments as the first guess and chooses between the
    /// two solutions when no goal is seen. (With the paper's method, global mode with the prior
    /// as the hint.)
    ///
    /// The robust method's decision rule, in either mode: an estimate is "not localized" (with
    /// the reason) unless
    /// - at least 20 boundary points were found where the floor meets a wall or a goal;
    /// - the fit converged with points on segments across both field axes, at least
    ///   `min_points_per_axis` on each;
    /// - it explains at least `min_inlier_fraction` of the boundary points (within `gate_mm`);
    /// - its weighted RMS residual is at most `max_rms_mm`;
    /// - the standard deviations of eq. (15)'s least squares (the residual variance times the
    ///   inverse normal matrix) are at most `max_sigma_mm` along each field axis and
    ///   `max_sigma_deg` in heading;
    /// - in global mode, no other first guess converges to a different pose (other than the
    ///   half-turn twin) that explains nearly as many points.
    pub fn track(
        &mut self,
        img: &RgbaImage,
        prior: &Isometry2<f64>,
    ) -> Result<Localization, VisionError> {
        if self.config.method == LocalizationMethod::Paper {
            return self.locate(img, Some(prior));
        }
        if let Some(why) = self.prepare(img)? {
            return Ok(Localization::NotLocalized(why));
        }
        Ok(self.locate_robust(img, Some(prior), Some(prior)))
    }

    /// Step 1 on the square around the circle where boundary points are taken; the reason
    /// there is nothing to localize from, if so.
    fn prepare(&mut self, img: &RgbaImage) -> Result<Option<String>, VisionError> {
        if img.width() != self.cal.width_px || img.height() != self.cal.height_px {
            return Err(VisionError::InvalidParameter {
                name: "image width (px)",
                value: img.width() as f64,
                rule: "must match the calibrated sensor's image size",
            });
        }
        let region = self.region();
        self.mask.binarize_region(img, &self.config.floor, region);
        self.mask
            .clean(self.config.morphology_iterations, &mut self.scratch);
        // The mask holds 0 or 1: a sum by rows of at most 255 pixels' worth in u16 lanes.
        let floor_pixels: usize = self
            .mask
            .data
            .chunks(255)
            .map(|c| c.iter().map(|&m| u16::from(m)).sum::<u16>() as usize)
            .sum();
        Ok((floor_pixels < self.config.min_floor_pixels).then(|| {
            format!(
                "floor region too small ({floor_pixels} pixels, need {})",
                self.config.min_floor_pixels
            )
        }))
    }

    /// The two solutions of a fitted field frame, the chosen one first: the goals' colours
    /// decide when seen, else the solution nearer `hint`, else the first.
    fn choose(
        &self,
        img: &RgbaImage,
        frame: &FieldFrame,
        hint: Option<&Isometry2<f64>>,
    ) -> (Isometry2<f64>, Isometry2<f64>, bool) {
        let (a, b) = frame.poses();
        match self.goal_vote(img, &a, &b) {
            Some(true) => (a, b, true),
            Some(false) => (b, a, true),
            None => match hint {
                Some(p) => {
                    let d =
                        |q: &Isometry2<f64>| (q.translation.vector - p.translation.vector).norm();
                    if d(&a) <= d(&b) {
                        (a, b, false)
                    } else {
                        (b, a, false)
                    }
                }
                None => (a, b, false),
            },
        }
    }

    /// The image region `[x0, y0, x1, y1)` around the circle of usable boundary points, with
    /// a margin for the morphology.
    fn region(&self) -> [usize; 4] {
        let r = self.config.max_radius_frac * self.cal.horizon_px + 3.0;
        let [cx, cy] = self.cal.principal_point_px;
        let (w, h) = (self.cal.width_px as f64, self.cal.height_px as f64);
        [
            (cx - r).floor().clamp(0.0, w) as usize,
            (cy - r).floor().clamp(0.0, h) as usize,
            (cx + r).ceil().clamp(0.0, w) as usize,
            (cy + r).ceil().clamp(0.0, h) as usize,
        ]
    }

    /// Which solution the goal colours support: `Some(true)` for `a`, `Some(false)` for `b`,
    /// `None` when no goal is seen or the vote is even.
    fn goal_vote(&self, img: &RgbaImage, a: &Isometry2<f64>, b: &Isometry2<f64>) -> Option<bool> {
        let [cx, cy] = self.cal.principal_point_px;
        let mut sums = [(0.0f64, 0.0f64, 0usize); 2];
        // Goals stand on the floor's far edge: look between the blind centre and the mirror's
        // edge only.
        let r_max = self.cal.horizon_px * 1.1;
        let (w, h) = (img.width() as i64, img.height() as i64);
        let u0 = (cx - r_max).floor().max(0.0) as i64;
        let u1 = ((cx + r_max).ceil() as i64).min(w);
        let v0 = (cy - r_max).floor().max(0.0) as i64;
        let v1 = ((cy + r_max).ceil() as i64).min(h);
        // Every other pixel of every other row (each standing for four): the goals' directions
        // are averages over many pixels.
        let raw = img.as_raw();
        let stride = w as usize * 4;
        for v in (v0..v1).step_by(2) {
            let row =
                &raw[v as usize * stride + u0 as usize * 4..v as usize * stride + u1 as usize * 4];
            for (u, p) in (u0..u1).step_by(2).zip(row.chunks(8)) {
                let rgb = [p[0], p[1], p[2]];
                let (pos, neg) = (
                    self.config.goal_pos_x.contains(rgb),
                    self.config.goal_neg_x.contains(rgb),
                );
                if !(pos | neg) {
                    continue;
                }
                let class = if pos { 0 } else { 1 };
                let x = u as f64 + 0.5 - cx;
                let y = cy - (v as f64 + 0.5);
                let r = x.hypot(y);
                if r < 1.0 {
                    continue;
                }
                sums[class].0 += x / r;
                sums[class].1 += y / r;
                sums[class].2 += 4;
            }
        }
        let a2 = self.config.field.a2_mm;
        let mut score = 0.0;
        for (class, goal_x) in [(0usize, a2), (1usize, -a2)] {
            let (sx, sy, n) = sums[class];
            if n < self.config.min_goal_pixels {
                continue;
            }
            let seen = sy.atan2(sx);
            let predicted = |pose: &Isometry2<f64>| {
                let q = pose.inverse_transform_point(&Point2::new(goal_x, 0.0));
                q.y.atan2(q.x)
            };
            // The rotation's angle reads back in (-pi, pi]: the angular error.
            let err_a = Rotation2::new(seen - predicted(a)).angle().abs();
            let err_b = Rotation2::new(seen - predicted(b)).angle().abs();
            score += err_b - err_a;
        }
        if score > 1e-9 {
            Some(true)
        } else if score < -1e-9 {
            Some(false)
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibration::tests::table as paper_calibration;
    use image::Rgba;
    use nalgebra::Vector2;

    const GREEN: Rgba<u8> = Rgba([30, 130, 55, 255]);
    const BROWN: Rgba<u8> = Rgba([120, 100, 80, 255]);
    const YELLOW: Rgba<u8> = Rgba([235, 200, 20, 255]);
    const BLUE: Rgba<u8> = Rgba([25, 60, 220, 255]);
    const GREY: Rgba<u8> = Rgba([40, 40, 40, 255]);
    const WHITE: Rgba<u8> = Rgba([235, 235, 235, 255]);

    /// A synthetic image of the field seen from `pose` (field frame) through the paper's
    /// f(R): floor inside the outline, goal colour just beyond the goal backs, a white wall
    /// band around the rest, a cube.
    fn field_image(pose: Isometry2<f64>, cube: Option<Point2<f64>>) -> RgbaImage {
        let cal = paper_calibration();
        let f = FieldModel::default();
        let mut img = RgbaImage::from_pixel(cal.width_px, cal.height_px, BROWN);
        for (u, v, px) in img.enumerate_pixels_mut() {
            let (x, y) = cal.image_coords(u as f64, v as f64);
            let Some(q) = cal.image_to_floor(x, y) else {
                continue;
            };
            let w = pose * q;
            let inside = (w.x.abs() <= f.a1_mm && w.y.abs() <= f.b_mm)
                || (w.x.abs() <= f.a2_mm && w.y.abs() <= f.goal_half_width_mm);
            if inside {
                *px = GREEN;
            } else if w.x.abs() <= f.a2_mm + 400.0 && w.y.abs() <= f.goal_half_width_mm + 60.0 {
                *px = if w.x > 0.0 { YELLOW } else { BLUE };
            } else if w.x.abs() <= f.a1_mm + 100.0 && w.y.abs() <= f.b_mm + 100.0 {
                *px = WHITE;
            }
            if cube.is_some_and(|c| (w.x - c.x).abs() <= 65.0 && (w.y - c.y).abs() <= 65.0) {
                *px = GREY;
            }
        }
        img
    }

    fn localize(pose: Isometry2<f64>, cube: Option<Point2<f64>>) -> Localization {
        let cal = paper_calibration();
        let mut l = FloorLocalizer::new(LocalizationConfig::default(), &cal).unwrap();
        l.locate(&field_image(pose, cube), None).unwrap()
    }

    #[test]
    fn the_fit_recovers_a_known_offset_and_rotation_from_exact_boundary_points() {
        // Boundary points sampled exactly on the six lines of a field shifted by (120, -80)
        // and turned by 0.05 rad, started from a deliberately wrong estimate.
        let cal = paper_calibration();
        let l = FloorLocalizer::new(LocalizationConfig::default(), &cal).unwrap();
        let f = FieldModel::default();
        let truth = Isometry2::new(Vector2::new(120.0, -80.0), 0.05);
        let mut pts = Vec::new();
        for k in 0..=40 {
            let t = -1.0 + 2.0 * k as f64 / 40.0;
            for p in [
                Point2::new(f.a2_mm, t * f.goal_half_width_mm),
                Point2::new(-f.a2_mm, t * f.goal_half_width_mm),
                Point2::new(t * f.a1_mm, f.b_mm),
                Point2::new(t * f.a1_mm, -f.b_mm),
                Point2::new(f.a1_mm, f.goal_half_width_mm + (t + 1.0) / 2.0 * 500.0),
                Point2::new(-f.a1_mm, -f.goal_half_width_mm - (t + 1.0) / 2.0 * 500.0),
            ] {
                pts.push(BoundaryPoint::new(truth * p, 1.0));
            }
        }
        let mut centre = Point2::new(60.0, -20.0);
        let mut psi = 0.0;
        for _ in 0..20 {
            let (du, dv, zeta, _, _, lines) = l.fit_step(&pts, centre, psi, 200.0).unwrap();
            assert_eq!(lines, 6);
            centre += Rotation2::new(psi) * Vector2::new(du, dv);
            psi += zeta;
        }
        assert!(
            (centre - Point2::new(120.0, -80.0)).norm() < 1e-6,
            "{centre}"
        );
        assert!((psi - 0.05).abs() < 1e-9, "{psi}");
    }

    #[test]
    fn synthetic_field_images_give_the_pose_and_the_goals_resolve_the_half_turn() {
        for (x, y, deg) in [
            (-900.0, 0.0, 0.0),
            (400.0, -400.0, 180.0),
            (850.0, 250.0, -135.0),
        ] {
            let truth = Isometry2::new(Vector2::new(x, y), f64::to_radians(deg));
            let Localization::Localized(e) = localize(truth, Some(Point2::new(250.0, 150.0)))
            else {
                panic!("not localized at ({x}, {y}, {deg})");
            };
            let d = (e.pose.translation.vector - truth.translation.vector).norm();
            let dh = (e.pose.rotation / truth.rotation).angle().abs();
            assert!(d < 30.0, "({x}, {y}, {deg}): position off by {d}");
            assert!(
                dh < 1f64.to_radians(),
                "({x}, {y}, {deg}): heading off by {dh}"
            );
            assert!(e.quality.resolved_by_goals);
            // The other solution is the half turn about the field centre.
            let alt = e.alternative.translation.vector;
            assert!((alt + e.pose.translation.vector).norm() < 1e-6);
        }
    }

    #[test]
    fn degenerate_images_are_not_localized() {
        let cal = paper_calibration();
        let mut l = FloorLocalizer::new(LocalizationConfig::default(), &cal).unwrap();
        for colour in [Rgba([0, 0, 0, 255]), Rgba([255, 255, 255, 255]), GREEN] {
            let img = RgbaImage::from_pixel(256, 220, colour);
            let r = l.locate(&img, None).unwrap();
            assert!(
                matches!(r, Localization::NotLocalized(_)),
                "{colour:?}: {r:?}"
            );
        }
        // A small green patch only.
        let mut img = RgbaImage::from_pixel(256, 220, BROWN);
        for v in 100..120 {
            for u in 120..140 {
                img.put_pixel(u, v, GREEN);
            }
        }
        assert!(matches!(
            l.locate(&img, None).unwrap(),
            Localization::NotLocalized(_)
        ));
        // The wrong image size is an error, not a panic.
        assert!(l.locate(&RgbaImage::new(10, 10), None).is_err());
    }
}
