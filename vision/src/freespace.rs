//! Free space around the robot from the floor region of an omnidirectional image
//! (Sect. 3.1 of the corner paper, steps 1-4).
//!
//! 1. Binarize by floor colour and clean with dilation/erosion ([`crate::mask`]).
//! 2. A polar template of I rings by J directions is laid on the image; each pixel belongs to
//!    one cell S_ij (ring i from the inside, direction j centred on the robot-frame angle
//!    `2 pi j / J`); one-pixel lines between cells keep them apart, as in Fig. 3 (c).
//! 3. The AND of floor mask and template is labelled into connected areas A_k with centroids
//!    p_k; eq. (5) `r_ij = (1 / A_ij) sum_{p_k in S_ij} A_k`, eq. (6) `q_ij = [r_ij >= r_th]`.
//!    The direct variant counts the floor pixels of each cell instead; since the template's
//!    lines keep every area inside one cell the two agree.
//! 4. Eq. (7): `a_j = min_{q_nj = 0} (n - 1)`, `n = 1..I+1`, `q_(I+1)j = 0`: the number of free
//!    cells from the inside before the first obstacle cell in direction j.
//!
//! Ring edges come from floor distances through `f^-1` or directly in pixels; the free distance
//! of direction j is the inner edge (mm) of its first obstacle cell, and the obstacle points are
//! that edge's arc (both ends and middle) in the robot frame.

use crate::VisionError;
use crate::calibration::RadialCalibration;
use crate::mask::{FloorColor, Mask};
use image::RgbaImage;
use nalgebra::{Isometry2, Point2, Vector2};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;
use std::sync::Arc;

/// How the ring edges are spaced between `inner_mm` and `outer_mm`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum RingSpacing {
    /// Equal steps of image radius (the paper's template, Fig. 3 (c)).
    #[default]
    Image,
    /// Equal steps of floor distance.
    Floor,
}

/// How r_ij is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum FreeSpaceMethod {
    /// Count the floor pixels of each cell.
    #[default]
    Count,
    /// Label the AND of floor mask and template and sum the areas by centroid (eq. (5)).
    Labeling,
}

/// Free-space settings (`[vision.freespace]` in scenarios).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FreeSpaceConfig {
    /// J: directions around the robot.
    pub directions: usize,
    /// I: rings from the inside out.
    pub rings: usize,
    /// Inner edge of the template on the floor (outside the blind zone of the robot's body).
    pub inner_mm: f64,
    /// Outer edge of the template on the floor.
    pub outer_mm: f64,
    /// Spacing of the ring edges between `inner_mm` and `outer_mm`.
    pub spacing: RingSpacing,
    /// Explicit ring edges on the floor (I + 1 increasing values), instead of the above.
    pub ring_edges_mm: Vec<f64>,
    /// Explicit ring edges in image radius (I + 1 increasing values), instead of the above.
    pub ring_edges_px: Vec<f64>,
    /// r_th of eq. (6): a cell with less floor than this fraction holds an obstacle.
    pub r_th: f64,
    /// How r_ij is computed.
    pub method: FreeSpaceMethod,
    /// Floor colour thresholds.
    pub floor: FloorColor,
    /// Dilation/erosion passes when cleaning the mask.
    pub morphology_iterations: u32,
    /// When the robot's own image (the dark disc about the mirror's axis) lies more than this
    /// many pixels from the calibration's principal point in the first frame, the template is
    /// laid about the disc's centre instead: a mirror shifted off its place moves its image
    /// (0: never).
    pub recentre_px: f64,
}

impl Default for FreeSpaceConfig {
    fn default() -> Self {
        Self {
            directions: 32,
            rings: 6,
            inner_mm: 200.0,
            outer_mm: 1000.0,
            spacing: RingSpacing::Image,
            ring_edges_mm: Vec::new(),
            ring_edges_px: Vec::new(),
            r_th: 0.5,
            method: FreeSpaceMethod::Count,
            floor: FloorColor::default(),
            morphology_iterations: 1,
            recentre_px: 1.0,
        }
    }
}

/// The result for one image.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FreeSpace {
    /// Centre angle of each direction j in the robot frame.
    pub direction_rad: Vec<f64>,
    /// a_j of eq. (7).
    pub a: Vec<usize>,
    /// Distance (mm, from the sensor axis) to the first obstacle cell of each direction, or to
    /// the template's outer edge when the direction is free throughout.
    pub free_mm: Vec<f64>,
    /// r_ij, ring-major (`r[i * J + j]`).
    pub ratio: Vec<f64>,
    /// Points on the near edge of each direction's first obstacle cell, robot frame.
    pub obstacle_points: Vec<Point2<f64>>,
    /// How far the template reaches (its outer edge on the floor): a direction free
    /// throughout is free this far, and nothing is known beyond.
    pub range_mm: f64,
    /// Where the template begins (its inner edge on the floor, from the sensor axis): the
    /// camera sees no floor nearer than that.
    pub inner_mm: f64,
    /// Per direction, how far the floor is free for certain: a cell judged free by eq. (6) may
    /// still be up to `1 - r_th` obstacle, so an obstacle (or, past the template, the unknown)
    /// may begin that deep inside the last free cell (computed with the obstacle filling the
    /// cell's outer part, on the image's pixel areas). The template's inner edge where the first
    /// ring is blocked.
    pub clear_mm: Vec<f64>,
    /// Points on the boundary of that surely free region, robot frame (three a direction,
    /// like `obstacle_points`).
    pub clear_points: Vec<Point2<f64>>,
    /// Per direction ending on an obstacle, the farthest its near face can be: it fills at
    /// least `1 - r_th` of the first blocked cell, so it begins no farther than where it would
    /// fill just the cell's outer part (computed as `clear_mm`, on the image's pixel areas).
    /// The face lies between `free_mm` and this; the template's range where the direction is
    /// free throughout.
    pub front_mm: Vec<f64>,
    /// Where the sensor axis stands in the robot frame, mm: the origin of every direction's
    /// distances.
    pub axis_mm: Point2<f64>,
    /// The floor region judged pixel by pixel in the image this came from (none once moved to
    /// another pose, [`FreeSpace::moved`]).
    pub pixels: Option<Arc<FloorPixels>>,
}

/// The floor region a detector judged in one image, pixel by pixel: step 1's cleaned floor mask
/// on the template's pixels, with the template, to be scored against a truth of the same
/// pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct FloorPixels {
    /// The template laid on the image.
    pub template: Arc<PolarTemplate>,
    /// Per pixel of the template's bounding box, row-major: non-zero where judged floor.
    pub floor: Vec<u8>,
    /// r_th of eq. (6).
    pub r_th: f64,
}

impl FloorPixels {
    /// Every pixel of the template (cell boundaries left out): its index in the bounding box,
    /// its image column and row.
    pub fn template_pixels(&self) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
        let [x0, y0, x1, _] = self.template.bbox;
        let bw = x1 - x0;
        (self.template.cells.iter().enumerate())
            .filter(|(_, c)| **c != NONE)
            .map(move |(k, _)| (k, x0 + k % bw, y0 + k / bw))
    }
}

impl FreeSpace {
    /// The free space as the robot sees it after moving by `motion` (its pose now in the robot
    /// frame of the frame that gave this free space), for a frame that arrives late or a cycle
    /// without one, so that the controller acts from where the robot is, not where the frame
    /// was taken. The directions stay the template's (fixed to the body); every point `p`
    /// becomes `motion^-1 p`; a direction's free distance is the nearest moved obstacle point
    /// inside its sector (measured from the sensor axis), or, with none there, the old
    /// direction's at the same bearing shortened by the displacement along it,
    /// `d - t . u` (exact for a face square to the ray), floored at 0; the same for the surely
    /// free distance with its boundary points. A direction free to the template's edge stays
    /// so (what lies beyond the edge was not seen from either place).
    pub fn moved(&self, motion: &Isometry2<f64>) -> FreeSpace {
        let back = motion.inverse();
        let t = motion.translation.vector;
        let turn = motion.rotation.angle();
        let points = |pts: &[Point2<f64>]| -> Vec<Point2<f64>> {
            pts.iter().map(|p| back.transform_point(p)).collect()
        };
        let obstacle_points = points(&self.obstacle_points);
        let clear_points = points(&self.clear_points);
        let free_mm = self.rebinned(&self.free_mm, &obstacle_points, t, turn);
        let clear_mm = self.rebinned(&self.clear_mm, &clear_points, t, turn);
        let front_mm = self.rebinned(&self.front_mm, &[], t, turn);
        FreeSpace {
            direction_rad: self.direction_rad.clone(),
            a: self.a.clone(),
            free_mm,
            ratio: self.ratio.clone(),
            obstacle_points,
            range_mm: self.range_mm,
            inner_mm: self.inner_mm,
            clear_mm,
            clear_points,
            front_mm,
            axis_mm: self.axis_mm,
            pixels: None,
        }
    }

    /// Per direction, the nearest of `moved` points in its sector, else `old`'s value at the
    /// same bearing (`turn` more in the old frame) less the displacement `t` along it.
    fn rebinned(&self, old: &[f64], moved: &[Point2<f64>], t: Vector2<f64>, turn: f64) -> Vec<f64> {
        let n = self.direction_rad.len();
        if n == 0 || old.len() != n {
            return old.to_vec();
        }
        let step = std::f64::consts::TAU / n as f64;
        let first = self.direction_rad[0];
        let index = |angle: f64| ((angle - first) / step).round().rem_euclid(n as f64) as usize % n;
        let mut nearest = vec![f64::INFINITY; n];
        for p in moved {
            let v = p - self.axis_mm;
            let j = index(v.y.atan2(v.x));
            nearest[j] = nearest[j].min(v.norm());
        }
        let edge = self.range_mm - 1e-9;
        (0..n)
            .map(|j| {
                if nearest[j].is_finite() {
                    return nearest[j];
                }
                let bearing = self.direction_rad[j] + turn;
                let d = old[index(bearing)];
                if d >= edge {
                    d
                } else {
                    (d - t.dot(&Vector2::new(bearing.cos(), bearing.sin()))).max(0.0)
                }
            })
            .collect()
    }
}

const NONE: u16 = u16::MAX;

/// The rings' edges in image pixels and on the floor (mm): as `config` gives them in mm or
/// in pixels, else `rings` + 1 edges evenly spaced in the image or on the floor from
/// `inner_mm` to `outer_mm`, each converted with the calibration.
fn ring_edges(
    config: &FreeSpaceConfig,
    cal: &RadialCalibration,
) -> Result<(Vec<f64>, Vec<f64>), VisionError> {
    let i_n = config.rings;
    let to_px = |mm: f64| {
        cal.image_radius_px(mm)
            .ok_or(VisionError::InvalidParameter {
                name: "ring edge (mm)",
                value: mm,
                rule: "must lie on the floor the sensor sees (inside the calibration table)",
            })
    };
    let to_mm = |px: f64| {
        cal.floor_distance_mm(px)
            .ok_or(VisionError::InvalidParameter {
                name: "ring edge (px)",
                value: px,
                rule: "must lie below the floor horizon of the calibration table",
            })
    };
    if !config.ring_edges_mm.is_empty() {
        let px = config
            .ring_edges_mm
            .iter()
            .map(|&m| to_px(m))
            .collect::<Result<Vec<_>, _>>()?;
        return Ok((px, config.ring_edges_mm.clone()));
    }
    if !config.ring_edges_px.is_empty() {
        let mm = config
            .ring_edges_px
            .iter()
            .map(|&p| to_mm(p))
            .collect::<Result<Vec<_>, _>>()?;
        return Ok((config.ring_edges_px.clone(), mm));
    }
    match config.spacing {
        RingSpacing::Image => {
            let (a, b) = (to_px(config.inner_mm)?, to_px(config.outer_mm)?);
            let px: Vec<f64> = (0..=i_n)
                .map(|k| a + (b - a) * k as f64 / i_n as f64)
                .collect();
            let mm = px
                .iter()
                .map(|&p| to_mm(p))
                .collect::<Result<Vec<_>, _>>()?;
            Ok((px, mm))
        }
        RingSpacing::Floor => {
            let (a, b) = (config.inner_mm, config.outer_mm);
            let mm: Vec<f64> = (0..=i_n)
                .map(|k| a + (b - a) * k as f64 / i_n as f64)
                .collect();
            let px = mm
                .iter()
                .map(|&m| to_px(m))
                .collect::<Result<Vec<_>, _>>()?;
            Ok((px, mm))
        }
    }
}

/// Checks there are `rings` + 1 edges (pixels), non-negative and strictly increasing.
fn check_ring_edges(edges_px: &[f64], rings: usize) -> Result<(), VisionError> {
    if edges_px.len() != rings + 1 {
        return Err(VisionError::InvalidParameter {
            name: "ring edges",
            value: edges_px.len() as f64,
            rule: "need rings + 1 edges",
        });
    }
    if edges_px.windows(2).any(|w| w[1] <= w[0]) || edges_px[0] < 0.0 {
        return Err(VisionError::InvalidParameter {
            name: "ring edges",
            value: edges_px[0],
            rule: "must be non-negative and strictly increasing",
        });
    }
    Ok(())
}

/// The cell (ring i, direction j: `i * directions + j`) of each pixel of the bounding box
/// `bbox` ([x0, y0, x1, y1)), `NONE` outside the rings.
fn label_pixels(
    cal: &RadialCalibration,
    edges_px: &[f64],
    directions: usize,
    bbox: [usize; 4],
) -> Vec<u16> {
    let [x0, y0, x1, y1] = bbox;
    let (bw, bh) = (x1 - x0, y1 - y0);
    let r_out = edges_px[edges_px.len() - 1];
    let dir_step = TAU / directions as f64;
    let mut raw = vec![NONE; bw * bh];
    for y in 0..bh {
        for x in 0..bw {
            let (px, py) = cal.image_coords((x + x0) as f64, (y + y0) as f64);
            let r = px.hypot(py);
            if r < edges_px[0] || r >= r_out {
                continue;
            }
            let i = edges_px.partition_point(|&e| e <= r) - 1;
            let phi = py.atan2(px);
            let j = ((phi / dir_step).round() as i64).rem_euclid(directions as i64) as usize;
            raw[y * bw + x] = (i * directions + j) as u16;
        }
    }
    raw
}

/// One-pixel lines between cells: a pixel of `raw` (`bw` x `bh`) whose right or lower
/// neighbour is in another cell (or outside) is left out.
fn cell_lines(raw: &[u16], bw: usize, bh: usize) -> Vec<u16> {
    let mut cells = raw.to_vec();
    for y in 0..bh {
        for x in 0..bw {
            let c = raw[y * bw + x];
            if c == NONE {
                continue;
            }
            let differs = |xx: isize, yy: isize| {
                if xx < 0 || yy < 0 || xx >= bw as isize || yy >= bh as isize {
                    return true;
                }
                raw[yy as usize * bw + xx as usize] != c
            };
            let (xi, yi) = (x as isize, y as isize);
            // Only the right/down neighbours mark a line, so lines are one pixel wide.
            if differs(xi + 1, yi) || differs(xi, yi + 1) {
                cells[y * bw + x] = NONE;
            }
        }
    }
    cells
}

/// The polar template laid on the image.
#[derive(Debug, Clone, PartialEq)]
pub struct PolarTemplate {
    rings: usize,
    directions: usize,
    edges_px: Vec<f64>,
    edges_mm: Vec<f64>,
    mount_mm: [f64; 2],
    /// Bounding box of the template, [x0, y0, x1, y1) in pixels.
    bbox: [usize; 4],
    /// Cell of each pixel in the bounding box (`NONE` outside or on a cell boundary).
    cells: Vec<u16>,
    /// A_ij: template pixels per cell.
    area: Vec<u32>,
}

impl PolarTemplate {
    /// Lays the template of `config` on images of the calibrated sensor.
    pub fn new(config: &FreeSpaceConfig, cal: &RadialCalibration) -> Result<Self, VisionError> {
        let (i_n, j_n) = (config.rings, config.directions);
        if i_n == 0 || j_n < 4 || i_n * j_n >= NONE as usize {
            return Err(VisionError::InvalidParameter {
                name: "rings x directions",
                value: (i_n * j_n) as f64,
                rule: "need rings >= 1, directions >= 4 and fewer than 65535 cells",
            });
        }
        let (edges_px, edges_mm) = ring_edges(config, cal)?;
        check_ring_edges(&edges_px, i_n)?;
        let (w, h) = (cal.width_px as usize, cal.height_px as usize);
        let [cx, cy] = cal.principal_point_px;
        let r_out = edges_px[i_n];
        let x0 = ((cx - r_out).floor().max(0.0)) as usize;
        let y0 = ((cy - r_out).floor().max(0.0)) as usize;
        let x1 = ((cx + r_out).ceil() as usize + 1).min(w);
        let y1 = ((cy + r_out).ceil() as usize + 1).min(h);
        let bbox = [x0, y0, x1, y1];
        let cells = cell_lines(&label_pixels(cal, &edges_px, j_n, bbox), x1 - x0, y1 - y0);
        let mut area = vec![0u32; i_n * j_n];
        for &c in &cells {
            if c != NONE {
                area[c as usize] += 1;
            }
        }
        if let Some(k) = area.iter().position(|&a| a == 0) {
            return Err(VisionError::InvalidParameter {
                name: "template cell area (px)",
                value: k as f64,
                rule: "every cell needs pixels inside the image: use fewer rings or directions, \
                       or edges inside the image",
            });
        }
        Ok(Self {
            rings: i_n,
            directions: j_n,
            edges_px,
            edges_mm,
            mount_mm: cal.mount_mm,
            bbox,
            cells,
            area,
        })
    }

    /// I.
    pub fn rings(&self) -> usize {
        self.rings
    }

    /// J.
    pub fn directions(&self) -> usize {
        self.directions
    }

    /// Ring edges in image radius.
    pub fn edges_px(&self) -> &[f64] {
        &self.edges_px
    }

    /// Ring edges on the floor.
    pub fn edges_mm(&self) -> &[f64] {
        &self.edges_mm
    }

    /// Bounding box of the template in the image, `[x0, y0, x1, y1)` in pixels.
    pub fn bbox(&self) -> [usize; 4] {
        self.bbox
    }

    /// Steps 2-4 with the count method on a floor mask of the template's bounding box (non-zero where
    /// floor): each cell's floor pixels over its area, eq. (5) as counted; eq. (6) against
    /// `r_th`; eq. (7)'s a_j per direction.
    pub fn judge(&self, floor: &[u8], r_th: f64) -> (Vec<f64>, Vec<usize>) {
        let mut counts = vec![0u32; self.rings * self.directions];
        for (&c, &m) in self.cells.iter().zip(floor) {
            if c != NONE && m != 0 {
                counts[c as usize] += 1;
            }
        }
        let ratio: Vec<f64> = (counts.iter().zip(&self.area))
            .map(|(&n, &a)| n as f64 / a as f64)
            .collect();
        let a = self.first_blocked(&ratio, r_th);
        (ratio, a)
    }

    /// Eq. (7): per direction j, the number of free cells from the inside before the first cell
    /// whose ratio is below `r_th` (I where none is).
    pub fn first_blocked(&self, ratio: &[f64], r_th: f64) -> Vec<usize> {
        let (i_n, j_n) = (self.rings, self.directions);
        (0..j_n)
            .map(|j| (0..i_n).find(|&i| ratio[i * j_n + j] < r_th).unwrap_or(i_n))
            .collect()
    }
}

/// Detects free space in images of one calibrated sensor.
#[derive(Debug, Clone)]
pub struct FreeSpaceDetector {
    config: FreeSpaceConfig,
    template: Arc<PolarTemplate>,
    /// Per ring, how far it is surely free when eq. (6) judges it free (see
    /// [`FreeSpace::clear_mm`]).
    surely_free_mm: Vec<f64>,
    principal_point_px: [f64; 2],
    mask: Mask,
    scratch: Vec<u8>,
    labels: Vec<u32>,
    parent: Vec<u32>,
    counts: Vec<u32>,
}

impl FreeSpaceDetector {
    /// A detector for images of the sensor `cal` describes.
    pub fn new(config: FreeSpaceConfig, cal: &RadialCalibration) -> Result<Self, VisionError> {
        if !(config.r_th > 0.0 && config.r_th <= 1.0) {
            return Err(VisionError::InvalidParameter {
                name: "r_th",
                value: config.r_th,
                rule: "must lie in (0, 1]",
            });
        }
        let template = Arc::new(PolarTemplate::new(&config, cal)?);
        let surely_free_mm = template
            .edges_px
            .windows(2)
            .zip(template.edges_mm.windows(2))
            .map(|(px, mm)| {
                let (r0, r1) = (px[0], px[1]);
                let r = (r1 * r1 - (1.0 - config.r_th) * (r1 * r1 - r0 * r0)).sqrt();
                cal.floor_distance_mm(r)
                    .unwrap_or(mm[0])
                    .clamp(mm[0], mm[1])
            })
            .collect();
        Ok(Self {
            surely_free_mm,
            counts: vec![0; config.rings * config.directions],
            config,
            template,
            principal_point_px: cal.principal_point_px,
            mask: Mask::new(0, 0),
            scratch: Vec::new(),
            labels: Vec::new(),
            parent: Vec::new(),
        })
    }

    /// The template.
    pub fn template(&self) -> &PolarTemplate {
        &self.template
    }

    /// The settings.
    pub fn config(&self) -> &FreeSpaceConfig {
        &self.config
    }

    /// The cleaned floor mask of the template's bounding box from the last image.
    pub fn mask(&self) -> &Mask {
        &self.mask
    }

    /// Runs steps 1-4 on one image.
    pub fn detect(&mut self, img: &RgbaImage) -> Result<FreeSpace, VisionError> {
        let [_, _, x1, y1] = self.template.bbox;
        if (img.width() as usize) < x1 || (img.height() as usize) < y1 {
            return Err(VisionError::InvalidParameter {
                name: "image size (px)",
                value: (img.width() * img.height()) as f64,
                rule: "smaller than the calibrated sensor's image",
            });
        }
        // Step 1 on the template's bounding box only.
        self.mask
            .binarize_region(img, &self.config.floor, self.template.bbox);
        self.mask
            .clean(self.config.morphology_iterations, &mut self.scratch);

        // Steps 2-3.
        let ratio = match self.config.method {
            FreeSpaceMethod::Count => self.template.judge(&self.mask.data, self.config.r_th).0,
            FreeSpaceMethod::Labeling => {
                let n_cells = self.config.rings * self.config.directions;
                self.counts.clear();
                self.counts.resize(n_cells, 0);
                self.label_areas();
                (self.counts.iter().zip(&self.template.area))
                    .map(|(&n, &a)| n as f64 / a as f64)
                    .collect()
            }
        };

        // Step 4.
        let (i_n, j_n) = (self.config.rings, self.config.directions);
        let dir_step = TAU / j_n as f64;
        let mut out = FreeSpace {
            direction_rad: (0..j_n).map(|j| j as f64 * dir_step).collect(),
            a: vec![i_n; j_n],
            free_mm: vec![0.0; j_n],
            ratio,
            obstacle_points: Vec::new(),
            range_mm: self.template.edges_mm[i_n],
            inner_mm: self.template.edges_mm[0],
            clear_mm: vec![0.0; j_n],
            clear_points: Vec::new(),
            front_mm: vec![self.template.edges_mm[i_n]; j_n],
            axis_mm: Point2::from(self.template.mount_mm),
            pixels: Some(Arc::new(FloorPixels {
                template: self.template.clone(),
                floor: self.mask.data.clone(),
                r_th: self.config.r_th,
            })),
        };
        let blocked = self.template.first_blocked(&out.ratio, self.config.r_th);
        let [mx, my] = self.template.mount_mm;
        for (j, &a) in blocked.iter().enumerate() {
            out.a[j] = a;
            let d = self.template.edges_mm[a];
            out.free_mm[j] = d;
            let c = out.direction_rad[j];
            let clear = if a == 0 {
                d
            } else {
                self.surely_free_mm[a - 1]
            };
            out.clear_mm[j] = clear;
            if a < i_n {
                out.front_mm[j] = self.surely_free_mm[a];
            }
            for phi in [c - 0.5 * dir_step, c, c + 0.5 * dir_step] {
                let u = (phi.cos(), phi.sin());
                if a < i_n {
                    out.obstacle_points
                        .push(Point2::new(mx + d * u.0, my + d * u.1));
                }
                out.clear_points
                    .push(Point2::new(mx + clear * u.0, my + clear * u.1));
            }
        }
        Ok(out)
    }

    /// Eq. (5) by labelling: 4-connected areas of (floor AND template), each area's pixels
    /// credited to the cell holding its centroid.
    fn label_areas(&mut self) {
        let [x0, y0, x1, _] = self.template.bbox;
        let bw = x1 - x0;
        let cells = &self.template.cells;
        let mask = &self.mask.data;
        let n = cells.len();
        self.labels.clear();
        self.labels.resize(n, u32::MAX);
        self.parent.clear();
        fn find(parent: &mut [u32], mut x: u32) -> u32 {
            while parent[x as usize] != x {
                parent[x as usize] = parent[parent[x as usize] as usize];
                x = parent[x as usize];
            }
            x
        }
        for k in 0..n {
            if cells[k] == NONE || mask[k] == 0 {
                continue;
            }
            let left = (k % bw > 0 && self.labels[k - 1] != u32::MAX).then(|| self.labels[k - 1]);
            let up = (k >= bw && self.labels[k - bw] != u32::MAX).then(|| self.labels[k - bw]);
            let label = match (left, up) {
                (None, None) => {
                    self.parent.push(self.parent.len() as u32);
                    self.parent.len() as u32 - 1
                }
                (Some(a), None) | (None, Some(a)) => a,
                (Some(a), Some(b)) => {
                    let (ra, rb) = (find(&mut self.parent, a), find(&mut self.parent, b));
                    if ra != rb {
                        self.parent[ra.max(rb) as usize] = ra.min(rb);
                    }
                    ra.min(rb)
                }
            };
            self.labels[k] = label;
        }
        // Area and centroid of each component.
        let m = self.parent.len();
        let mut area = vec![0u32; m];
        let mut sx = vec![0f64; m];
        let mut sy = vec![0f64; m];
        for k in 0..n {
            let l = self.labels[k];
            if l == u32::MAX {
                continue;
            }
            let root = find(&mut self.parent, l) as usize;
            area[root] += 1;
            sx[root] += (k % bw) as f64;
            sy[root] += (k / bw) as f64;
        }
        let [cx, cy] = self.principal_point_px;
        let (i_n, j_n) = (self.config.rings, self.config.directions);
        let edges = &self.template.edges_px;
        let dir_step = TAU / j_n as f64;
        for root in 0..m {
            if area[root] == 0 {
                continue;
            }
            let a = area[root] as f64;
            let u = sx[root] / a + x0 as f64;
            let v = sy[root] / a + y0 as f64;
            let (px, py) = (u + 0.5 - cx, cy - (v + 0.5));
            let r = px.hypot(py);
            if r < edges[0] || r >= edges[i_n] {
                continue;
            }
            let i = edges.partition_point(|&e| e <= r) - 1;
            let j = ((py.atan2(px) / dir_step).round() as i64).rem_euclid(j_n as i64) as usize;
            self.counts[i * j_n + j] += area[root];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    /// Eight directions; a wall square to direction 0 at 500 mm (three points on it), the
    /// other directions free to the 1000 mm edge.
    fn wall_ahead() -> FreeSpace {
        let n = 8;
        let mut free_mm = vec![1000.0; n];
        free_mm[0] = 500.0;
        FreeSpace {
            direction_rad: (0..n)
                .map(|j| j as f64 * std::f64::consts::TAU / 8.0)
                .collect(),
            a: vec![0; n],
            free_mm: free_mm.clone(),
            ratio: Vec::new(),
            obstacle_points: vec![
                Point2::new(500.0, -30.0),
                Point2::new(500.0, 0.0),
                Point2::new(500.0, 30.0),
            ],
            range_mm: 1000.0,
            inner_mm: 200.0,
            clear_mm: free_mm.clone(),
            clear_points: Vec::new(),
            front_mm: free_mm,
            axis_mm: Point2::origin(),
            pixels: None,
        }
    }

    #[test]
    fn moved_free_space_is_seen_from_where_the_robot_is_now() {
        let fs = wall_ahead();
        // 100 mm forward: the wall is 400 mm ahead; nothing else changes.
        let ahead = fs.moved(&Isometry2::new(Vector2::new(100.0, 0.0), 0.0));
        assert!(
            (ahead.free_mm[0] - 400.0).abs() < 1e-9,
            "{:?}",
            ahead.free_mm
        );
        assert!(ahead.free_mm[1..].iter().all(|d| *d == 1000.0));
        assert_eq!(ahead.obstacle_points[1], Point2::new(400.0, 0.0));
        // Turned 90 degrees to the left on the spot: the wall is now to the right
        // (direction 6, -90 degrees), 500 mm away; directions stay the body's.
        let turned = fs.moved(&Isometry2::new(
            Vector2::zeros(),
            std::f64::consts::FRAC_PI_2,
        ));
        assert_eq!(turned.direction_rad, fs.direction_rad);
        assert!(
            (turned.free_mm[6] - 500.0).abs() < 1e-9,
            "{:?}",
            turned.free_mm
        );
        assert_eq!(turned.free_mm[0], 1000.0);
        // Without points (the surely free distance here), the shortening along the bearing.
        assert!((ahead.front_mm[0] - 400.0).abs() < 1e-9);
        assert!((turned.front_mm[6] - 500.0).abs() < 1e-9);
        // No motion: the same free space.
        let still = fs.moved(&Isometry2::identity());
        assert_eq!(still.free_mm, fs.free_mm);
        assert_eq!(still.obstacle_points, fs.obstacle_points);
    }

    use crate::calibration::tests::table as paper_calibration;

    const GREEN: Rgba<u8> = Rgba([30, 130, 55, 255]);
    const GREY: Rgba<u8> = Rgba([90, 90, 90, 255]);

    /// An image whose pixels are floor unless `obstacle(floor point)` says otherwise.
    fn synthetic(cal: &RadialCalibration, obstacle: impl Fn(Point2<f64>) -> bool) -> RgbaImage {
        let mut img = RgbaImage::from_pixel(cal.width_px, cal.height_px, GREEN);
        for (u, v, p) in img.enumerate_pixels_mut() {
            let (x, y) = cal.image_coords(u as f64, v as f64);
            match cal.image_to_floor(x, y) {
                Some(q) if obstacle(q) => *p = GREY,
                None => *p = GREY,
                _ => {}
            }
        }
        img
    }

    #[test]
    fn an_open_floor_is_free_in_every_direction() {
        let cal = paper_calibration();
        let mut d = FreeSpaceDetector::new(FreeSpaceConfig::default(), &cal).unwrap();
        let fs = d.detect(&synthetic(&cal, |_| false)).unwrap();
        assert!(fs.a.iter().all(|&a| a == 6), "{:?}", fs.a);
        assert!(fs.obstacle_points.is_empty());
        assert!(fs.free_mm.iter().all(|&m| (m - 1000.0).abs() < 1e-6));
    }

    #[test]
    fn obstacles_filling_cells_give_the_rings_they_stand_in() {
        let cal = paper_calibration();
        for method in [FreeSpaceMethod::Count, FreeSpaceMethod::Labeling] {
            let config = FreeSpaceConfig {
                method,
                spacing: RingSpacing::Floor,
                ..FreeSpaceConfig::default()
            };
            // Edges 200, 333, 467, 600, 733, 867, 1000 mm. Obstacles: beyond 480 mm within 20
            // degrees of straight ahead (fills ring 2 of directions 31, 0, 1 but only 28% of
            // direction 2), and beyond 620 mm between 40 and 50 degrees (direction 4, ring 3).
            let mut d = FreeSpaceDetector::new(config, &cal).unwrap();
            let img = synthetic(&cal, |q| {
                let r = q.coords.norm();
                let phi = q.y.atan2(q.x).to_degrees();
                (r >= 480.0 && phi.abs() < 20.0) || (r >= 620.0 && (40.0..50.0).contains(&phi))
            });
            let fs = d.detect(&img).unwrap();
            for j in [31, 0, 1] {
                assert_eq!(fs.a[j], 2, "{method:?} direction {j}: {:?}", fs.a);
                assert!((fs.free_mm[j] - 1400.0 / 3.0).abs() < 1e-6);
            }
            assert_eq!(fs.a[2], 6, "{method:?}: {:?}", fs.a);
            assert_eq!(fs.a[4], 3, "{method:?}: {:?}", fs.a);
            assert!((fs.free_mm[4] - 600.0).abs() < 1e-6);
            for j in 6..=29 {
                assert_eq!(fs.a[j], 6, "{method:?} direction {j}");
            }
            // Obstacle points lie on the near edge of the first obstacle cell, three a direction.
            assert_eq!(fs.obstacle_points.len(), 12);
            assert!(
                fs.obstacle_points
                    .iter()
                    .all(|p| (p.coords.norm() - 1400.0 / 3.0).abs() < 1e-6
                        || (p.coords.norm() - 600.0).abs() < 1e-6)
            );
        }
    }

    #[test]
    fn small_holes_are_closed_but_a_cube_is_seen() {
        let cal = paper_calibration();
        let mut d = FreeSpaceDetector::new(FreeSpaceConfig::default(), &cal).unwrap();
        // A 130 mm cube at 500 mm to the left, plus single-pixel salt.
        let mut img = synthetic(&cal, |q| (q.x).abs() <= 65.0 && (q.y - 565.0).abs() <= 65.0);
        for k in 0..200u32 {
            img.put_pixel((k * 37) % 256, (k * 53) % 220, GREY);
        }
        let fs = d.detect(&img).unwrap();
        // Direction 8 (90 degrees) sees the cube; its neighbours at +-22.5 degrees do not.
        assert!(fs.a[8] < 6, "{:?}", fs.a);
        // The first obstacle ring overlaps the cube's radial extent, 500..630 mm.
        let edges = d.template().edges_mm();
        let a = fs.a[8];
        assert!(
            edges[a] < 630.0 && edges[a + 1] > 500.0,
            "{edges:?} a = {a}"
        );
        assert_eq!(fs.a[6], 6);
        assert_eq!(fs.a[10], 6);
        assert_eq!(fs.a[0], 6);
    }

    #[test]
    fn degenerate_templates_are_refused() {
        let cal = paper_calibration();
        let bad = FreeSpaceConfig {
            outer_mm: 1e6,
            ..FreeSpaceConfig::default()
        };
        assert!(FreeSpaceDetector::new(bad, &cal).is_err());
        let bad = FreeSpaceConfig {
            r_th: 0.0,
            ..FreeSpaceConfig::default()
        };
        assert!(FreeSpaceDetector::new(bad, &cal).is_err());
    }
}
