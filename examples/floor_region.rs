//! The free-space stage's floor region beside the truth's, for one frame of a run: the frame,
//! the floor the stage judged on its template's pixels (step 1 of Sect. 3.1 of the corner
//! paper, its cleaned floor-colour mask), the true floor region from the truth's labels, and
//! where they differ (red: judged floor but not; blue: floor judged not). Prints the cycle's
//! intersection over union, as `estimates.jsonl` records it with `omniloop run --truth`:
//! `cargo run --release --example floor_region -- scenarios/corner55_velocity_aware.toml 60 docs/truth_floor_region.png`

use anyhow::{Context, bail};
use image::{Rgb, RgbImage, imageops};
use omniloop::run::RunOptions;
use omniloop::run::score::FloorRegionScore;
use omniloop::vision::{FreeSpaceConfig, FreeSpaceDetector};
use omniloop::{Simulation, load_scenario};
use omniloop_sim::RendererChoice;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [scenario, cycle, out] = args.as_slice() else {
        bail!("usage: floor_region SCENARIO CYCLE OUT.png");
    };
    let s = load_scenario(scenario.as_ref())?;
    let cycle: u64 = cycle.parse().context("CYCLE is a whole number")?;
    let options = RunOptions {
        renderer: RendererChoice::Cpu,
        truth: true,
        takes_frames: true,
        ..RunOptions::default()
    };
    let mut sim = Simulation::new(&s, &options, |m| eprintln!("{m}"))?;
    while sim.cycle() < cycle && !sim.finished() {
        sim.step()?;
    }
    sim.sense()?;
    let camera = &s.robot.sensors[s.vision_sensor_index().map_err(anyhow::Error::msg)?].name;
    let agent = &sim.robots()[0];
    let frame = (agent
        .frames()
        .into_iter()
        .find(|f| f.sensor == camera.as_str()))
    .context("no frame of vision's camera this cycle")?;
    let truth = (agent
        .truth_frames()
        .into_iter()
        .find(|(c, _)| *c == camera.as_str()))
    .context("no truth this cycle")?
    .1;
    let config: FreeSpaceConfig = s.vision.table("freespace")?;
    let cal = sim
        .vision_calibration()
        .context("vision's camera has no calibration")?;
    let fs = FreeSpaceDetector::new(config, cal)?.detect(frame.image)?;
    let pixels = fs.pixels.context("the detector judged no pixels")?;
    let score = FloorRegionScore::of(&pixels, truth, Vec::new());
    let (w, h) = (truth.width, truth.height);
    let frame_rgb = image::DynamicImage::ImageRgba8(frame.image.clone()).to_rgb8();
    let blank = RgbImage::new(w, h);
    let mut panels = [frame_rgb, blank.clone(), blank.clone(), blank];
    let (floor, other) = (Rgb([60, 170, 80]), Rgb([70, 70, 70]));
    for (k, u, v) in pixels.template_pixels() {
        let (e, t) = (
            pixels.floor[k] != 0,
            truth.is_floor_region((v as u32 * w) as usize + u),
        );
        let (u, v) = (u as u32, v as u32);
        panels[1].put_pixel(u, v, if e { floor } else { other });
        panels[2].put_pixel(u, v, if t { floor } else { other });
        let diff = match (e, t) {
            (true, false) => Rgb([230, 40, 40]),
            (false, true) => Rgb([40, 90, 240]),
            _ => {
                if e {
                    floor
                } else {
                    other
                }
            }
        };
        panels[3].put_pixel(u, v, diff);
    }
    let gap = 8;
    let mut sheet = RgbImage::from_pixel(4 * w + 3 * gap, h, Rgb([255, 255, 255]));
    for (i, p) in panels.iter().enumerate() {
        imageops::replace(&mut sheet, p, i64::from(i as u32 * (w + gap)), 0);
    }
    sheet.save(out).with_context(|| format!("writing {out}"))?;
    println!(
        "{}, cycle {}: floor region IoU {:.4}, false free {:.4}, false blocked {:.4} -> {out}",
        s.name,
        sim.cycle(),
        score.iou,
        score.false_free,
        score.false_blocked
    );
    Ok(())
}
