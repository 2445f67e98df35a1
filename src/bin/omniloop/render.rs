//! `omniloop render`: one frame of a sensor to a PNG, with its truth when asked.

use super::load;
use anyhow::{Context, bail};
use nalgebra::{Isometry2, Vector2};
use omniloop::run::{render_snapshot, render_snapshot_truth, truth_files};
use omniloop_sim::render::TruthFrame;
use omniloop_sim::{Renderer, RendererChoice};
use std::path::{Path, PathBuf};

/// `omniloop render`'s arguments.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// Scenario file.
    scenario: PathBuf,
    /// Robot pose `x_mm,y_mm,theta_deg` (default: the scenario's start).
    #[arg(long, allow_hyphen_values = true)]
    pose: Option<String>,
    /// Output PNG.
    #[arg(long)]
    out: PathBuf,
    /// Sensor name (default: the robot's first sensor).
    #[arg(long)]
    sensor: Option<String>,
    /// Renderer: auto, gpu or cpu.
    #[arg(long, default_value = "auto")]
    renderer: RendererChoice,
    /// Leave out the sensor noise.
    #[arg(long)]
    no_noise: bool,
    /// Write the frame's truth beside it: OUT's stem with `_depth.png` (16-bit, mm),
    /// `_labels.png` (indexed) and `_legend.json`.
    #[arg(long)]
    truth: bool,
}

/// `omniloop render`: one frame of a sensor, with its truth when asked.
pub fn render_cmd(args: RenderArgs) -> anyhow::Result<()> {
    let RenderArgs {
        scenario,
        pose,
        out,
        sensor,
        renderer,
        no_noise,
        truth,
    } = args;
    let s = load(&scenario)?;
    let pose = pose.as_deref().map(parse_pose).transpose()?;
    let mut r = Renderer::new(renderer, |msg| eprintln!("{msg}"))?;
    let (img, truth) = if truth {
        let (img, t) = render_snapshot_truth(&s, &mut r, sensor.as_deref(), pose, !no_noise)?;
        (img, Some(t))
    } else {
        (
            render_snapshot(&s, &mut r, sensor.as_deref(), pose, !no_noise)?,
            None,
        )
    };
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
    }
    img.save(&out)
        .with_context(|| format!("writing {}", out.display()))?;
    if let Some(t) = &truth {
        for file in write_snapshot_truth(&out, t)? {
            println!("truth -> {}", file.display());
        }
    }
    println!(
        "{}: {}x{} rendered by {} -> {}",
        s.name,
        img.width(),
        img.height(),
        r.name(),
        out.display()
    );
    Ok(())
}

/// A pose `x_mm,y_mm,theta_deg` of the command line.
fn parse_pose(text: &str) -> anyhow::Result<Isometry2<f64>> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let nums: Result<Vec<f64>, _> = parts.iter().map(|p| p.parse::<f64>()).collect();
    match nums {
        Ok(v) if v.len() == 3 && v.iter().all(|x| x.is_finite()) => {
            Ok(Isometry2::new(Vector2::new(v[0], v[1]), v[2].to_radians()))
        }
        _ => bail!("--pose {text:?}: expected x_mm,y_mm,theta_deg, e.g. --pose -900,0,45"),
    }
}

/// Writes a snapshot's truth beside its image `out`: `STEM_depth.png`, `STEM_labels.png` and
/// `STEM_legend.json`; returns the files.
fn write_snapshot_truth(out: &Path, truth: &TruthFrame) -> anyhow::Result<Vec<PathBuf>> {
    let dir = out.parent().unwrap_or(Path::new(""));
    let stem = out
        .file_stem()
        .map_or("frame".into(), |s| s.to_string_lossy().into_owned());
    truth_files::write_truth(dir, &stem, truth)?;
    let legend = dir.join(format!("{stem}_legend.json"));
    truth_files::write_legend(&legend, truth)?;
    Ok(["depth.png", "labels.png"]
        .iter()
        .map(|k| dir.join(format!("{stem}_{k}")))
        .chain([legend])
        .collect())
}
