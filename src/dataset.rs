//! `omniloop dataset`: frames of a scenario's camera with their truth, for training and
//! evaluating perception on catadioptric images.
//!
//! The folder holds (`docs/truth.md`):
//! - `images/NNNNNN.png`: the frame as the robot's software gets it (RGB, with the sensor's
//!   noise and effects);
//! - `depth/NNNNNN.png`: 16-bit depth, mm (0: unknown or sky);
//! - `labels/NNNNNN.png`: 8-bit indexed labels, `legend.json` their legend;
//! - `poses.csv`: `sample,t_s,x_mm,y_mm,theta_rad`, the robot's true pose at each frame;
//! - `calibration.json`: the camera's image-to-floor map (`omniloop calibrate`), and for a
//!   mirror camera `camera.yaml` with `camera.json`, the fitted unified model
//!   (`omniloop calibrate --format opencv-omnidir`);
//! - `dataset.json`: what made it (scenario, seed, sensor, sizes, pose mode) and these names.
//!
//! Poses are drawn at random over the floor (`random`: seeded by the scenario's seed, the
//! robot clear of every solid and robot by its radius, heading uniform) or taken along the
//! scenario's own run (`along-run`: every k-th cycle of the run).

use crate::camera_export::{CameraFormat, ExportError, export_camera_model};
use crate::run::{RunError, RunOptions, Simulation, truth_files};
use crate::scenario::calibrate::calibrate_sensor;
use crate::scenario::{Scenario, SensorLookupError};
use image::RgbaImage;
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_sim::render::TruthFrame;
use omniloop_sim::{Renderer, RendererChoice, Scene, SensorNoise, SensorSpec, World};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// Where the dataset's poses come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum PoseMode {
    /// Drawn at random over the floor, clear of every solid and robot.
    #[default]
    Random,
    /// Along the scenario's own run.
    AlongRun,
}

impl PoseMode {
    /// Its name on the command line and in `dataset.json`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Random => "random",
            Self::AlongRun => "along-run",
        }
    }
}

/// A pose mode's name that is none of them.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown pose mode {0:?} (random, along-run)")]
pub struct UnknownPoseMode(pub String);

impl FromStr for PoseMode {
    type Err = UnknownPoseMode;
    fn from_str(s: &str) -> Result<Self, UnknownPoseMode> {
        match s {
            "random" => Ok(Self::Random),
            "along-run" => Ok(Self::AlongRun),
            other => Err(UnknownPoseMode(other.to_string())),
        }
    }
}

/// How to make a dataset.
#[derive(Debug, Clone)]
pub struct DatasetOptions {
    /// Frames to write.
    pub samples: usize,
    /// Where the poses come from.
    pub poses: PoseMode,
    /// The camera (default: the one vision uses, else the robot's first).
    pub sensor: Option<String>,
    /// The renderer.
    pub renderer: RendererChoice,
}

impl Default for DatasetOptions {
    fn default() -> Self {
        Self {
            samples: 100,
            poses: PoseMode::Random,
            sensor: None,
            renderer: RendererChoice::Cpu,
        }
    }
}

/// What went wrong making a dataset.
#[derive(Debug, thiserror::Error)]
pub enum DatasetError {
    /// The scenario cannot give such a dataset (no such camera, no room for the robot).
    #[error("scenario {scenario:?}: {why}")]
    Scenario {
        /// The scenario's name.
        scenario: String,
        /// Why.
        why: String,
    },
    /// The scenario's robot has no such camera.
    #[error("scenario {scenario:?}: {error}")]
    Sensor {
        /// The scenario's name.
        scenario: String,
        /// Which camera, and which there are.
        error: SensorLookupError,
    },
    /// The run or the renderer failed.
    #[error(transparent)]
    Run(#[from] RunError),
    /// A file could not be written.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why (in the message, not a separate cause).
        reason: std::io::Error,
    },
    /// A frame could not be written.
    #[error("{path}: {reason}")]
    Image {
        /// The file.
        path: PathBuf,
        /// Why (in the message, not a separate cause).
        reason: image::ImageError,
    },
    /// The camera model could not be fitted.
    #[error(transparent)]
    Export(#[from] ExportError),
}

/// What a dataset holds, written as `dataset.json`.
#[derive(Debug, Clone, Serialize)]
pub struct DatasetInfo {
    /// Always `omniloop-truth-dataset`.
    pub format: &'static str,
    /// The layout's version.
    pub version: u32,
    /// The scenario's name.
    pub scenario: String,
    /// Its seed.
    pub seed: u64,
    /// The camera.
    pub sensor: String,
    /// Image width and height, px.
    pub size_px: [u32; 2],
    /// Frames written.
    pub samples: usize,
    /// Where the poses came from.
    pub poses: PoseMode,
    /// The folders and files, by role.
    pub files: DatasetFiles,
}

/// The names in a dataset's folder.
#[derive(Debug, Clone, Serialize)]
pub struct DatasetFiles {
    /// Frames: `images/NNNNNN.png`.
    pub images: &'static str,
    /// Depth: `depth/NNNNNN.png`.
    pub depth: &'static str,
    /// Labels: `labels/NNNNNN.png`.
    pub labels: &'static str,
    /// The labels' legend.
    pub legend: &'static str,
    /// The true poses.
    pub poses: &'static str,
    /// The image-to-floor map.
    pub calibration: Option<&'static str>,
    /// The fitted camera model (a mirror camera).
    pub camera_model: Option<&'static str>,
}

/// One frame with its truth and the pose it was taken at.
struct Sample {
    image: RgbaImage,
    truth: TruthFrame,
    t_s: f64,
    pose: Isometry2<f64>,
}

/// Writes `options.samples` frames of `scenario`'s camera with their truth into `out`;
/// `progress` gets (written, samples) after each. Returns what it wrote.
pub fn write_dataset(
    scenario: &Scenario,
    options: &DatasetOptions,
    out: &Path,
    mut progress: impl FnMut(usize, usize),
) -> Result<DatasetInfo, DatasetError> {
    let sensor_name = options
        .sensor
        .as_deref()
        .or(scenario.vision.sensor.as_deref());
    let index = scenario
        .sensor_index(sensor_name)
        .map_err(|error| DatasetError::Sensor {
            scenario: scenario.name.clone(),
            error,
        })?;
    let spec = scenario.robot.sensors[index].clone();
    for dir in ["images", "depth", "labels"] {
        create_dir(&out.join(dir))?;
    }
    let mut poses = String::from("sample,t_s,x_mm,y_mm,theta_rad\n");
    let mut legend_written = false;
    let mut save = |k: usize, s: Sample| -> Result<(), DatasetError> {
        let name = format!("{k:06}.png");
        let path = out.join("images").join(&name);
        let rgb: image::RgbImage = image::buffer::ConvertBuffer::convert(&s.image);
        rgb.save(&path)
            .map_err(|reason| DatasetError::Image { path, reason })?;
        truth_files::write_depth_png(&out.join("depth").join(&name), &s.truth)
            .map_err(RunError::from)?;
        truth_files::write_label_png(&out.join("labels").join(&name), &s.truth)
            .map_err(RunError::from)?;
        if !legend_written {
            truth_files::write_legend(&out.join("legend.json"), &s.truth)
                .map_err(RunError::from)?;
            legend_written = true;
        }
        let p = s.pose;
        poses += &format!(
            "{k},{},{},{},{}\n",
            s.t_s,
            p.translation.x,
            p.translation.y,
            p.rotation.angle()
        );
        progress(k + 1, options.samples);
        Ok(())
    };
    let written = match options.poses {
        PoseMode::Random => random_samples(scenario, index, options, &mut save)?,
        PoseMode::AlongRun => run_samples(scenario, &spec, options, &mut save)?,
    };
    write_file(&out.join("poses.csv"), poses.as_bytes())?;
    let (calibration, camera_model) = write_camera_files(&spec, out)?;
    let info = DatasetInfo {
        format: "omniloop-truth-dataset",
        version: 1,
        scenario: scenario.name.clone(),
        seed: scenario.seed,
        sensor: spec.name.clone(),
        size_px: [spec.width_px, spec.height_px],
        samples: written,
        poses: options.poses,
        files: DatasetFiles {
            images: "images",
            depth: "depth",
            labels: "labels",
            legend: "legend.json",
            poses: "poses.csv",
            calibration,
            camera_model,
        },
    };
    // A plain record of numbers and strings always serialises.
    let text = serde_json::to_string_pretty(&info).unwrap_or_default();
    write_file(&out.join("dataset.json"), (text + "\n").as_bytes())?;
    Ok(info)
}

/// The camera's image-to-floor map and, for a mirror, its fitted unified model.
fn write_camera_files(
    spec: &SensorSpec,
    out: &Path,
) -> Result<(Option<&'static str>, Option<&'static str>), DatasetError> {
    let calibration = match calibrate_sensor(spec) {
        Ok(cal) if !cal.samples.is_empty() => {
            let path = out.join("calibration.json");
            cal.save(&path).map_err(|e| DatasetError::Io {
                path,
                reason: std::io::Error::other(e.to_string()),
            })?;
            Some("calibration.json")
        }
        _ => None,
    };
    let model = match export_camera_model(spec, CameraFormat::OpencvOmnidir) {
        Ok(e) => {
            write_file(&out.join("camera.yaml"), e.text.as_bytes())?;
            let json = serde_json::to_string_pretty(&e.json).unwrap_or_default();
            write_file(&out.join("camera.json"), (json + "\n").as_bytes())?;
            Some("camera.yaml")
        }
        Err(ExportError::NotAMirror(_)) => None,
        Err(e) => return Err(e.into()),
    };
    Ok((calibration, model))
}

/// Frames at random poses over the floor.
fn random_samples(
    scenario: &Scenario,
    index: usize,
    options: &DatasetOptions,
    save: &mut impl FnMut(usize, Sample) -> Result<(), DatasetError>,
) -> Result<usize, DatasetError> {
    let own = scenario.member(0);
    let sensor = own.robot.sensors[index].build();
    let bodies = scenario.robot_bodies();
    let mut world = World::new(&scenario.world, &bodies, scenario.run.physics_step_s)
        .map_err(RunError::from)?;
    let mut renderer =
        Renderer::new(options.renderer, |m| eprintln!("{m}")).map_err(RunError::from)?;
    let seed = crate::run::cameras::sensor_noise_seed(own.seed, index);
    let mut noise = SensorNoise::new(seed);
    let mut places = FreePlaces::new(scenario, &world, bodies[0].radius_mm);
    for k in 0..options.samples {
        let pose = places.draw().ok_or_else(|| DatasetError::Scenario {
            scenario: scenario.name.clone(),
            why: format!(
                "no pose found on the floor clear of every solid by the robot's radius {} mm \
                 after {} tries",
                bodies[0].radius_mm,
                FreePlaces::TRIES
            ),
        })?;
        world.place_robot(0, pose);
        let scene = Scene::of_world(&world);
        let (image, truth) = renderer
            .render_exposed_truth(&scene, &sensor, &[pose], Some(&mut noise))
            .map_err(RunError::from)?;
        let t_s = 0.0;
        save(
            k,
            Sample {
                image,
                truth,
                t_s,
                pose,
            },
        )?;
    }
    Ok(options.samples)
}

/// Poses drawn uniformly over the floor's bounds, kept where the robot stands on the floor
/// region clear of every solid and other robot.
struct FreePlaces<'a> {
    solids: Vec<omniloop_sim::Solid>,
    layout: &'a omniloop_sim::Layout,
    radius_mm: f64,
    bounds: [f64; 4],
    others: Vec<(Point2<f64>, f64)>,
    rng: StdRng,
}

impl<'a> FreePlaces<'a> {
    /// Draws before giving up on one pose.
    const TRIES: usize = 100_000;

    fn new(scenario: &'a Scenario, world: &World, radius_mm: f64) -> Self {
        let rects = scenario.world.all_floor_rects();
        // Each floor rectangle's bounding square about its centre.
        let corners = rects.iter().flat_map(|r| {
            let c = Point2::from(r.center_mm);
            let h = 0.5 * r.size_mm[0].hypot(r.size_mm[1]);
            [c - Vector2::new(h, h), c + Vector2::new(h, h)]
        });
        let solids = (world.solids().iter()).flat_map(|s| {
            let (c, r) = s.shape.bounding_circle();
            [c - Vector2::new(r, r), c + Vector2::new(r, r)]
        });
        let mut bounds = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for p in corners.chain(solids) {
            bounds = [
                bounds[0].min(p.x),
                bounds[1].min(p.y),
                bounds[2].max(p.x),
                bounds[3].max(p.y),
            ];
        }
        if !bounds.iter().all(|b| b.is_finite()) {
            // An open floor: around the start.
            let s = scenario.start().point();
            bounds = [s.x - 2000.0, s.y - 2000.0, s.x + 2000.0, s.y + 2000.0];
        }
        let others = (scenario.robot_bodies().iter().skip(1))
            .map(|b| (Point2::from(b.start.translation.vector), b.radius_mm))
            .collect();
        Self {
            solids: world.solids().to_vec(),
            layout: &scenario.world,
            radius_mm,
            bounds,
            others,
            rng: StdRng::seed_from_u64(scenario.seed ^ 0xDA7A_5E70_0000_0001),
        }
    }

    /// A free pose, if one is found within [`FreePlaces::TRIES`] draws.
    fn draw(&mut self) -> Option<Isometry2<f64>> {
        let [x0, y0, x1, y1] = self.bounds;
        for _ in 0..Self::TRIES {
            let p = Point2::new(
                self.rng.random_range(x0..=x1),
                self.rng.random_range(y0..=y1),
            );
            let theta = self
                .rng
                .random_range(-std::f64::consts::PI..std::f64::consts::PI);
            if self.is_free(p) {
                return Some(Isometry2::new(p.coords, theta));
            }
        }
        None
    }

    fn is_free(&self, p: Point2<f64>) -> bool {
        let r = self.radius_mm;
        self.layout.is_floor(p)
            && (self.solids.iter()).all(|s| s.shape.distance_mm(p) > r)
            && (self.others.iter()).all(|(c, rc)| (p - c).norm() > r + rc)
    }
}

/// The cycles of the scenario's run (it may stop at the goal before its time is up): the run
/// itself, without its cameras' frames.
fn run_cycles(scenario: &Scenario) -> Result<u64, DatasetError> {
    let options = RunOptions {
        renderer: RendererChoice::Cpu,
        ..RunOptions::default()
    };
    let mut sim = Simulation::new(scenario, &options, |_| {})?;
    while !sim.finished() {
        sim.step()?;
    }
    Ok(sim.cycle())
}

/// Frames along the scenario's run: every k-th cycle, k spreading the samples over the run
/// (counted by running it once first; the same seed gives the same run).
fn run_samples(
    scenario: &Scenario,
    spec: &SensorSpec,
    options: &DatasetOptions,
    save: &mut impl FnMut(usize, Sample) -> Result<(), DatasetError>,
) -> Result<usize, DatasetError> {
    let run = RunOptions {
        renderer: options.renderer,
        // Every camera rendered (none saved), with its truth.
        save_frames_every: Some(1),
        truth: true,
        ..RunOptions::default()
    };
    let mut sim = Simulation::new(scenario, &run, |m| eprintln!("{m}"))?;
    let every = (run_cycles(scenario)? / options.samples.max(1) as u64).max(1);
    let mut written = 0;
    while written < options.samples && !sim.finished() {
        let cycle = sim.cycle();
        sim.sense()?;
        let pose = sim.truth().pose;
        let t_s = sim.world().time_s();
        if cycle.is_multiple_of(every) {
            let agent = &sim.robots()[0];
            let frame = agent.frames().into_iter().find(|f| f.sensor == spec.name);
            let truth = (agent.truth_frames().into_iter()).find(|(s, _)| *s == spec.name);
            if let (Some(f), Some((_, t))) = (frame, truth) {
                let sample = Sample {
                    image: f.image.clone(),
                    truth: t.clone(),
                    t_s,
                    pose,
                };
                save(written, sample)?;
                written += 1;
            }
        }
        sim.act()?;
    }
    Ok(written)
}

fn create_dir(dir: &Path) -> Result<(), DatasetError> {
    std::fs::create_dir_all(dir).map_err(|reason| DatasetError::Io {
        path: dir.to_path_buf(),
        reason,
    })
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<(), DatasetError> {
    std::fs::File::create(path)
        .and_then(|mut f| f.write_all(bytes))
        .map_err(|reason| DatasetError::Io {
            path: path.to_path_buf(),
            reason,
        })
}
