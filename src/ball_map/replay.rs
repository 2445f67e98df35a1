//! The replay: every camera's map, then the false balls of E1's camera, written as
//! `ball_map.md`, `ball_map.csv`, `ball_map.png` and `summary.json`.

use super::measure::{self, Measured};
use super::report;
use super::scenes::{CAMERAS, Camera, E1, EMPTY, FIELD, scenario_text};
use super::spec::BallMapSpec;
use super::stats::{CameraMap, FalseBalls};
use crate::experiments::{Replay, ReplayContext};
use crate::run::{RunOptions, Simulation};
use anyhow::Context;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// `omniloop replay ball_map`.
pub const REPLAY: Replay = Replay {
    name: "ball_map",
    title: "the ball detector's error map: detection, range and bearing error by distance for \
            four mirror cameras, and false balls in ball-free frames",
    run: replay,
};

/// Ball-free frames of E1's camera in the replay.
pub const EMPTY_FRAMES: usize = 1000;

/// What the replay measured (`summary.json`).
#[derive(Debug, Clone, Serialize)]
pub struct BallMapReplay {
    /// The runs' seed.
    pub seed: u64,
    /// The placements of every camera's map.
    pub spec: BallMapSpec,
    /// Every camera's map, in the tables' order.
    pub cameras: Vec<CameraMap>,
    /// The camera of the ball-free frames.
    pub false_ball_camera: String,
    /// What the ball-free frames showed.
    pub false_balls: FalseBalls,
    /// Frames taken in all.
    pub frames: usize,
    /// Wall time, s.
    pub wall_s: f64,
}

/// Runs every camera's map and the ball-free frames; writes the outputs into the context's
/// folder and returns `ball_map.md`.
fn replay(ctx: &mut ReplayContext<'_>) -> anyhow::Result<String> {
    let started = Instant::now();
    let spec = BallMapSpec::default();
    let mut csv = format!("{}\n", report::CSV_HEADER);
    let mut cameras = Vec::new();
    let mut frames = 0;
    let mut seed = 0;
    for cam in &CAMERAS {
        let (m, s) = measure_camera(ctx, ("ball_map", FIELD), cam, &spec)?;
        report::csv_rows(cam.title, &m.rows, &mut csv);
        frames += m.rows.len();
        seed = s;
        let mut map = CameraMap::of(&m, spec.target_range_mm)
            .with_context(|| format!("{}: no frame with the ball", cam.title))?;
        map.camera = cam.title.to_string();
        cameras.push(map);
    }
    let empty = BallMapSpec {
        empty_frames: EMPTY_FRAMES,
        ..BallMapSpec::default()
    };
    let (m, _) = measure_camera(ctx, ("false_balls", EMPTY), &E1, &empty)?;
    report::csv_rows(E1.title, &m.rows, &mut csv);
    frames += m.rows.len();
    let false_balls = FalseBalls::of(&m).context("the ball-free run took no frame")?;
    let result = BallMapReplay {
        seed,
        spec,
        cameras,
        false_ball_camera: E1.title.to_string(),
        false_balls,
        frames,
        wall_s: started.elapsed().as_secs_f64(),
    };
    write_outputs(ctx.out, &result, &csv)
}

/// The frames of `cam` in the scene (`run`: its name and text) as `spec` places them, and the
/// run's seed.
fn measure_camera(
    ctx: &mut ReplayContext<'_>,
    (run, scene): (&str, &str),
    cam: &Camera,
    spec: &BallMapSpec,
) -> anyhow::Result<(Measured, u64)> {
    let file = format!("{run}_{}.toml", cam.id);
    let text = scenario_text(scene, cam, spec).context("writing [experiment.ball_map]")?;
    let mut s = (ctx.load)(&text, Path::new(&file), "ball_map")?;
    if let Some(v) = crate::scenario::validate(&s).first() {
        anyhow::bail!("{file}: field `{}`: {}", v.field, v.message);
    }
    if let Some(seed) = ctx.seed {
        s.seed = seed;
    }
    let options = RunOptions {
        renderer: ctx.options.renderer,
        takes_frames: true,
        ..RunOptions::default()
    };
    let notice = &mut *ctx.notice;
    let mut sim = Simulation::new(&s, &options, |m| notice(m))
        .with_context(|| format!("building the run of {file}"))?;
    let name = format!("{run} {}", cam.id);
    let progress = &mut *ctx.progress;
    let m = measure::run(&mut sim, spec, &mut |k, n| progress(&name, k, n))
        .with_context(|| format!("running {file}"))?;
    Ok((m, s.seed))
}

/// `ball_map.md`.
pub fn markdown(r: &BallMapReplay) -> String {
    let spec = &r.spec;
    let (first, last) = (
        spec.distances_mm.first().copied().unwrap_or(0.0),
        spec.distances_mm.last().copied().unwrap_or(0.0),
    );
    let mut s = String::from("# Ball-detection error map\n\n");
    let _ = writeln!(
        s,
        "The ball (the league's 43 mm orange ball) at {} distances from {first:.0} to {last:.0} \
         mm in {} directions round E1's robot body (each turned by a seeded random part of the \
         {:.0}-degree step, the robot's heading drawn at random), {} frames each with the \
         camera's noise: {} frames a camera, and {} ball-free frames; {} frames in all, seed \
         {}, {:.0} s. Range and bearing are the ball centre's from the robot's centre; the \
         errors are over the frames with a sighting; \"in sight\" leaves out the frames where \
         the body hides the ball's top.\n",
        spec.distances_mm.len(),
        spec.directions,
        360.0 / spec.directions as f64,
        spec.draws,
        spec.frames(true),
        r.false_balls.frames,
        r.frames,
        r.seed,
        r.wall_s
    );
    s += &report::summary_table(&r.cameras);
    let _ = writeln!(
        s,
        "\n{}\n",
        report::false_ball_line(&r.false_ball_camera, &r.false_balls)
    );
    s += "## By distance\n\n";
    for m in &r.cameras {
        s += &report::camera_table(m);
        s += "\n";
    }
    s
}

/// Writes `ball_map.md`, `ball_map.csv`, `ball_map.png` and `summary.json` into `dir`;
/// returns the Markdown.
pub fn write_outputs(dir: &Path, r: &BallMapReplay, csv: &str) -> anyhow::Result<String> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let md = markdown(r);
    let json = serde_json::to_string_pretty(r).context("writing summary.json")?;
    let files = [
        ("ball_map.md", md.clone().into_bytes()),
        ("ball_map.csv", csv.as_bytes().to_vec()),
        ("ball_map.png", report::figure(&r.cameras)?),
        ("summary.json", (json + "\n").into_bytes()),
    ];
    for (name, bytes) in files {
        let file = dir.join(name);
        std::fs::write(&file, bytes).with_context(|| format!("writing {}", file.display()))?;
    }
    Ok(md)
}
