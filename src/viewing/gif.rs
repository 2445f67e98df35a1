//! An animated GIF of a run (`omniloop run --gif FILE`), for READMEs and papers: every `k`-th
//! cycle, each camera's image beside the top view with the true and estimated paths so far,
//! played at the simulation's pace.

use crate::report::output::run_topview_image;
use crate::run::RunOutput;
use crate::run::observer::{CycleObserver, CycleView, ObserverHandle};
use crate::scenario::Scenario;
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, RgbaImage, imageops};
use std::path::Path;
use std::sync::{Arc, Mutex};

/// Width of the top view in the animation, px.
const TOP_VIEW_PX: u32 = 420;

/// The frames an animation keeps while the run goes on.
struct Kept {
    every: u64,
    /// (cycle, each robot's cameras' images).
    frames: Vec<(usize, Vec<Vec<RgbaImage>>)>,
}

impl CycleObserver for Kept {
    fn cycle(&mut self, v: &CycleView<'_>) {
        if v.cycle.is_multiple_of(self.every) {
            let images = v
                .robots
                .iter()
                .map(|r| r.frames.iter().map(|f| f.image.clone()).collect())
                .collect();
            self.frames.push((v.cycle as usize, images));
        }
    }
}

/// An animation of a run being made: keeps every `k`-th cycle's frames; drawn when the run is
/// over ([`GifLog::write`]).
pub struct GifLog {
    kept: Arc<Mutex<Kept>>,
}

impl GifLog {
    /// Keeps every `every`-th cycle (at least 1).
    pub fn new(every: u64) -> Self {
        Self {
            kept: Arc::new(Mutex::new(Kept {
                every: every.max(1),
                frames: Vec::new(),
            })),
        }
    }

    /// What the run's options take to keep the frames.
    pub fn observer(&self) -> ObserverHandle {
        let shared: Arc<Mutex<dyn CycleObserver>> = self.kept.clone();
        ObserverHandle(shared)
    }

    /// Draws each kept cycle (its cameras left, a robot a column in a team, the top view with
    /// the paths up to it right)
    /// and writes the animation to `file`, each frame shown as long as the cycles it stands for
    /// took; returns how many frames it has.
    pub fn write(&self, file: &Path, s: &Scenario, out: &RunOutput) -> anyhow::Result<usize> {
        use anyhow::Context as _;
        let kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        let period_ms = s.run.control_period_s * 1000.0 * kept.every as f64;
        let delay = Delay::from_numer_denom_ms(period_ms.round().max(10.0) as u32, 1);
        let name = file.display().to_string();
        let mut frames = Vec::with_capacity(kept.frames.len());
        for (cycle, images) in &kept.frames {
            let top = run_topview_image(&name, s, &up_to(out, cycle + 1), TOP_VIEW_PX)?;
            frames.push(Frame::from_parts(side_by_side(images, &top), 0, 0, delay));
        }
        let f = std::fs::File::create(file).with_context(|| format!("writing {name}"))?;
        let count = frames.len();
        let mut encoder = GifEncoder::new_with_speed(std::io::BufWriter::new(f), 20);
        encoder
            .set_repeat(Repeat::Infinite)
            .and_then(|()| encoder.encode_frames(frames))
            .with_context(|| format!("writing {name}"))?;
        Ok(count)
    }
}

/// What the top view draws of the run's first `n` cycles: its paths so far (no records).
fn up_to(out: &RunOutput, n: usize) -> RunOutput {
    let head = |v: &[nalgebra::Point2<f64>]| v[..n.min(v.len())].to_vec();
    RunOutput {
        summary: out.summary.clone(),
        trajectory: out.trajectory[..n.min(out.trajectory.len())].to_vec(),
        estimates: Vec::new(),
        floor_scores: Vec::new(),
        other_paths: out.other_paths.iter().map(|p| head(p)).collect(),
        files: Vec::new(),
        map: out.map.clone(),
        robots: out
            .robots
            .iter()
            .map(|r| crate::run::RobotOutput {
                name: r.name.clone(),
                trajectory: r.trajectory[..n.min(r.trajectory.len())].to_vec(),
                estimates: Vec::new(),
                floor_scores: Vec::new(),
                map: None,
            })
            .collect(),
        ball: out.ball.as_ref().map(|b| crate::run::BallOutput {
            rows: b.rows[..n.min(b.rows.len())].to_vec(),
            events: Vec::new(),
        }),
    }
}

/// Each robot's camera images stacked in a column of its own on the left (a team's robots in
/// up to four columns, the rows below), the top view on the right, on white.
fn side_by_side(robots: &[Vec<RgbaImage>], top: &image::RgbImage) -> RgbaImage {
    let columns = robots.len().clamp(1, 4);
    let cell_w = robots
        .iter()
        .flatten()
        .map(RgbaImage::width)
        .max()
        .unwrap_or(0);
    let cell_h = robots
        .iter()
        .map(|images| images.iter().map(RgbaImage::height).sum::<u32>())
        .max()
        .unwrap_or(0);
    let rows = robots.len().div_ceil(columns) as u32;
    let left_w = cell_w * columns as u32;
    let (w, h) = (left_w + top.width(), (cell_h * rows).max(top.height()));
    let mut canvas = RgbaImage::from_pixel(w, h, image::Rgba([255, 255, 255, 255]));
    for (k, images) in robots.iter().enumerate() {
        let x = cell_w * (k % columns) as u32;
        let mut y = cell_h * (k / columns) as u32;
        for img in images {
            imageops::overlay(&mut canvas, img, i64::from(x), i64::from(y));
            y += img.height();
        }
    }
    let top = image::DynamicImage::ImageRgb8(top.clone()).into_rgba8();
    imageops::overlay(&mut canvas, &top, i64::from(left_w), 0);
    canvas
}
