//! The truth beside a frame, pixel by pixel: how far the light travelled to the camera, where
//! it left the floor and what it came from.
//!
//! The tracers give each pixel the distance along its scene ray to what the ray meets and what
//! that is (a [`Code`]: a primitive's rank, the floor's paint or the sky). This module adds the
//! mirror half of the path, traced once per sensor in `f64` ([`TruthRays`]), and turns the codes
//! into the labels of the scene's [`Legend`]. It is the simulator's side only: none of it
//! reaches the robot's software.

use super::scene::Scene;
use super::trace::{self, CODE_FLOOR, CODE_NOTHING, CODE_SKY, Code, FloorPaint};
use crate::labels::{self, Legend};
use crate::sensor::Sensor;
use nalgebra::Isometry2;
use rayon::prelude::*;

/// The truth of one frame, row-major like the image.
#[derive(Debug, Clone, PartialEq)]
pub struct TruthFrame {
    /// Image width, px.
    pub width: u32,
    /// Image height, px.
    pub height: u32,
    /// How far the light travelled from what the pixel shows to the camera's viewpoint: the
    /// scene ray to the mirror plus the camera ray from the mirror to the lens (mm). Infinity
    /// for the sky, NaN where the pixel sees no mirror.
    pub depth_mm: Vec<f32>,
    /// Where the pixel shows the floor, the floor point's horizontal distance from the robot's
    /// centre (mm); NaN elsewhere.
    pub floor_mm: Vec<f32>,
    /// What the pixel shows: a label of [`TruthFrame::legend`].
    pub labels: Vec<u16>,
    /// The labels' legend.
    pub legend: Legend,
}

impl TruthFrame {
    /// The label of pixel `(u, v)`.
    pub fn label(&self, u: u32, v: u32) -> u16 {
        self.labels[(v * self.width + u) as usize]
    }

    /// Whether the pixel shows the floor region: bare floor or a line painted on it (marks and
    /// floor outside the region left out).
    pub fn is_floor_region(&self, k: usize) -> bool {
        matches!(self.labels[k], labels::FLOOR_REGION | labels::FLOOR_LINE)
    }
}

/// The mirror half of each pixel's path for the truth, in the robot frame (the same for every
/// pose), traced in `f64` and kept in `f32`: the camera ray's length to the mirror, and the
/// scene ray's origin and direction across the floor (x, y).
#[derive(Debug, Clone)]
pub struct TruthRays {
    /// Per pixel, the camera ray's length (mm); NaN where the pixel sees no mirror.
    path_mm: Vec<f32>,
    /// Per pixel, the scene ray's origin x, y (mm) and direction x, y, each in an array of its
    /// own.
    rays: [Vec<f32>; 4],
}

impl TruthRays {
    /// Traces the mirror half of every pixel of `sensor`.
    pub fn new(sensor: &Sensor) -> Self {
        let (w, h) = (sensor.width_px, sensor.height_px);
        let (mut path_mm, mut rays) = (Vec::new(), <[Vec<f32>; 4]>::default());
        for (u, v) in (0..h).flat_map(|v| (0..w).map(move |u| (u, v))) {
            let ray = sensor.pixel_ray(u, v);
            path_mm.push(ray.map_or(f32::NAN, |r| r.path_mm as f32));
            let parts = ray.map_or([0.0; 4], |r| [r.origin.x, r.origin.y, r.dir.x, r.dir.y]);
            for (a, c) in rays.iter_mut().zip(parts) {
                a.push(c as f32);
            }
        }
        Self { path_mm, rays }
    }

    /// How many pixels.
    pub fn len(&self) -> usize {
        self.path_mm.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.rays.is_empty()
    }
}

/// The cylinder of `scene` that is the robot's own body at `pose`: the one standing at its
/// centre.
pub fn own_body(scene: &Scene, pose: &Isometry2<f64>) -> Option<usize> {
    let (px, py) = (pose.translation.x as f32, pose.translation.y as f32);
    scene
        .cylinders
        .iter()
        .position(|cy| cy.geom[0] == px && cy.geom[1] == py)
}

/// The label of each [`Code`] a frame of `scene` can hold, for a robot whose body is cylinder
/// `body`.
struct Labeller {
    /// The label of each code's place in the table ([`Labeller::place`]): nothing for rank 0
    /// (none), the ranks' from 1, the floor paints', then the sky's and nothing's.
    table: Vec<u16>,
    /// The number of ranks (primitives).
    ranks: u32,
}

impl Labeller {
    fn new(scene: &Scene, legend: &Legend, body: Option<usize>) -> Self {
        let first_cylinder = scene.boxes.len() + scene.quads.len();
        let ranks = (scene.objects.iter().enumerate()).map(|(k, &o)| match body {
            Some(b) if k == first_cylinder + b => labels::OWN_BODY,
            _ => legend.label(o),
        });
        let paints = (0..scene.floor_rects.len() as u32 + 3).map(|k| {
            match trace::paint_of_index(scene, k) {
                FloorPaint::Mark(_) => labels::FLOOR_MARK,
                FloorPaint::Outside => labels::FLOOR_OUTSIDE,
                FloorPaint::Line => labels::FLOOR_LINE,
                FloorPaint::Floor => labels::FLOOR_REGION,
            }
        });
        let table = [labels::NOTHING]
            .into_iter()
            .chain(ranks)
            .chain(paints)
            .chain([labels::SKY, labels::NOTHING])
            .collect();
        Self {
            table,
            ranks: scene.objects.len() as u32,
        }
    }

    /// A code's place in the table, by selects rather than branches (a frame's codes change
    /// class often along the rows): a rank is its own place, a floor paint `p` follows the
    /// ranks, the sky and nothing close the table.
    #[inline]
    fn place(&self, code: Code) -> usize {
        let last = self.table.len() as u32 - 1;
        let paint = self.ranks + 1 + (code & !CODE_FLOOR);
        let place = if code & CODE_FLOOR == 0 { code } else { paint };
        let place = if code == CODE_SKY { last - 1 } else { place };
        let place = if code == CODE_NOTHING { last } else { place };
        place.min(last) as usize
    }

    fn label(&self, code: Code) -> u16 {
        self.table[self.place(code)]
    }
}

/// The truth of a frame of `sensor` (its mirror half in `rays`) on a robot at `pose` in
/// `scene`, from each pixel's distance `t` along its scene ray and what it meets, `codes`.
pub fn truth_frame(
    scene: &Scene,
    sensor: &Sensor,
    rays: &TruthRays,
    pose: &Isometry2<f64>,
    t: &[f32],
    codes: &[Code],
) -> TruthFrame {
    let legend = scene.legend();
    let labeller = Labeller::new(scene, &legend, own_body(scene, pose));
    let n = rays.len().min(t.len()).min(codes.len());
    // In parallel over the cores, in runs of rows, each a plain loop (whose pixels the
    // compiler sees together, however it inlines the parallel iterator).
    let mut labels = vec![labels::NOTHING; n];
    (labels.par_chunks_mut(PIXELS_A_TASK))
        .zip(codes[..n].par_chunks(PIXELS_A_TASK))
        .zip(rays.path_mm[..n].par_chunks(PIXELS_A_TASK))
        .for_each(|((out, codes), paths)| {
            for ((label, &code), path) in out.iter_mut().zip(codes).zip(paths) {
                let code = if path.is_nan() { CODE_NOTHING } else { code };
                *label = labeller.label(code);
            }
        });
    // The sky's distance is infinite, a pixel that sees no mirror has none (its path is NaN):
    // the sum holds both.
    let depth_mm: Vec<f32> = (rays.path_mm[..n].par_iter())
        .with_min_len(PIXELS_A_TASK)
        .zip(&t[..n])
        .map(|(path, t)| path + t)
        .collect();
    let floor_mm = floor_distances(&rays.rays, &t[..n], &codes[..n]);
    TruthFrame {
        width: sensor.width_px,
        height: sensor.height_px,
        depth_mm,
        floor_mm,
        labels,
        legend,
    }
}

/// Where a pixel shows the floor (`codes`), the floor point's distance from the robot's centre:
/// `|o + t d|` across the floor, from the scene rays `[o_x, o_y, d_x, d_y]` in the robot frame;
/// NaN elsewhere.
fn floor_distances(rays: &[Vec<f32>; 4], t: &[f32], codes: &[Code]) -> Vec<f32> {
    let n = t.len().min(codes.len());
    let [ox, oy, dx, dy] = rays.each_ref().map(|a| &a[..n]);
    let mut out = vec![f32::NAN; n];
    (out.par_chunks_mut(PIXELS_A_TASK).enumerate()).for_each(|(c, chunk)| {
        let first = c * PIXELS_A_TASK;
        for (i, out) in chunk.iter_mut().enumerate() {
            let k = first + i;
            let (x, y) = (ox[k] + t[k] * dx[k], oy[k] + t[k] * dy[k]);
            let floor = (codes[k] & CODE_FLOOR != 0) & (codes[k] < CODE_NOTHING);
            *out = if floor {
                (x * x + y * y).sqrt()
            } else {
                f32::NAN
            };
        }
    });
    out
}

/// Pixels a task of the truth's conversion takes at least.
const PIXELS_A_TASK: usize = 8192;
