//! The closed loop: sense, decide, act, record, once a control period.

use crate::estimator::PoseTracker;
use crate::metrics::{corner_metrics, median};
use crate::record::PlaceResult;
use crate::record::{Summary, TrajectoryRow};
use crate::scenario::PoseSource;
use crate::scenario::{ControllerKind, Scenario, controller_name};
use nalgebra::{Point2, Rotation2, Vector2};
use omniloop_control::{
    AccelLimitedDrive, GoToGoal, GoalDirection, Surroundings, VelocityAware, VelocityCommand,
};
use omniloop_sim::{
    RenderError, Renderer, RendererChoice, Scene, Sensor, SensorNoise, SimError, World,
};
use omniloop_vision::{
    FloorLocalizer, FreeSpace, FreeSpaceDetector, Localization, RadialCalibration, VisionError,
};
use std::path::PathBuf;
use std::time::Instant;

/// Why a run could not be carried out.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The world could not be built.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// A controller could not be built.
    #[error("control: {0}")]
    Control(#[from] omniloop_control::ControlError),
    /// The renderer could not open or render.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// Vision could not be set up.
    #[error("vision: {0}")]
    Vision(#[from] VisionError),
    /// A frame could not be written.
    #[error("writing frame {path}: {source}")]
    Frame {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: image::ImageError,
    },
}

/// How to run a scenario (what the command line adds to the scenario file).
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Which renderer traces the sensors' images.
    pub renderer: RendererChoice,
    /// Save every sensor's image every this many cycles (with `frames_dir`).
    pub save_frames_every: Option<u64>,
    /// Where saved frames go.
    pub frames_dir: Option<PathBuf>,
}

/// The seed of sensor `index`'s noise, derived from the run's seed.
pub fn sensor_noise_seed(seed: u64, index: usize) -> u64 {
    seed ^ (index as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15)
}

/// The sensors of the robot under test, their noise and the renderer, when images are needed.
struct Eyes {
    renderer: Renderer,
    sensors: Vec<(Sensor, SensorNoise)>,
}

/// Drives another robot through its waypoints on its true pose.
struct Mover {
    waypoints: Vec<Point2<f64>>,
    next: usize,
    cycle: bool,
    controller: GoToGoal,
}

/// Everything a run produced.
#[derive(Debug, Clone)]
pub struct RunOutput {
    /// Metrics.
    pub summary: Summary,
    /// One row a control cycle.
    pub trajectory: Vec<TrajectoryRow>,
    /// The paths of the other robots, one point a control cycle.
    pub other_paths: Vec<Vec<Point2<f64>>>,
}

/// What chooses the robot's command.
enum Brain {
    Idle,
    Truth(GoToGoal),
    GoalDirection(GoalDirection),
    VelocityAware(VelocityAware),
}

/// Free-space detection on one sensor's images.
struct Vision {
    sensor: usize,
    detector: FreeSpaceDetector,
    range_mm: f64,
    mount_mm: [f64; 2],
}

/// Floor-region self-localization on one sensor's images.
struct Localizer {
    sensor: usize,
    localizer: FloorLocalizer,
}

/// A scenario being run, one control cycle at a time.
pub struct Simulation {
    scenario: Scenario,
    world: World,
    brain: Brain,
    vision: Option<Vision>,
    localizer: Option<Localizer>,
    tracker: PoseTracker,
    targets: Vec<Point2<f64>>,
    next_target: usize,
    pose_errors_mm: Vec<f64>,
    movers: Vec<Mover>,
    cycle: u64,
    time_to_goal_s: Option<f64>,
    trajectory: Vec<TrajectoryRow>,
    other_paths: Vec<Vec<Point2<f64>>>,
    freespace_errors_mm: Vec<f64>,
    eyes: Option<Eyes>,
    options: RunOptions,
    last_freespace: Option<FreeSpace>,
}

/// The calibration vision uses: the scenario's file, or the sensor's traced map.
fn vision_calibration(scenario: &Scenario, index: usize) -> Result<RadialCalibration, RunError> {
    match &scenario.vision.calibration_file {
        Some(path) => Ok(RadialCalibration::load(path)?),
        None => Ok(crate::calibrate::calibrate_sensor(
            &scenario.robot.sensors[index],
        )?),
    }
}

impl Simulation {
    /// Builds the world and controllers of a validated scenario. `notice` receives one-line
    /// messages for the user (e.g. the renderer falling back to the CPU).
    pub fn new(
        scenario: &Scenario,
        options: &RunOptions,
        notice: impl FnOnce(&str),
    ) -> Result<Self, RunError> {
        let world = World::new(
            &scenario.world,
            &scenario.robot_bodies(),
            scenario.run.physics_step_s,
        )?;
        let r = &scenario.robot;
        let drive = AccelLimitedDrive::new(r.accel_limit_mm_s2, r.angular_accel_limit_rad_s2)?;
        let avoid = scenario.control.avoidance.clone();
        let brain = match scenario.control.kind {
            ControllerKind::Idle => Brain::Idle,
            ControllerKind::GoToGoalTruth => Brain::Truth(GoToGoal::new(r.max_speed_mm_s, drive)?),
            ControllerKind::GoalDirection => Brain::GoalDirection(GoalDirection::new(
                avoid,
                drive,
                r.max_speed_mm_s,
                r.radius_mm,
            )?),
            ControllerKind::VelocityAware => Brain::VelocityAware(VelocityAware::new(
                avoid,
                drive,
                r.max_speed_mm_s,
                r.radius_mm,
                scenario.run.control_period_s,
            )?),
        };
        let localizes = scenario.experiment.is_some()
            || (scenario.control.kind.uses_vision()
                && scenario.control.pose_source == PoseSource::Localization);
        let vision_sensor = || -> Result<usize, RunError> {
            Ok(match &scenario.vision.sensor {
                Some(n) => r.sensors.iter().position(|s| &s.name == n),
                None => (!r.sensors.is_empty()).then_some(0),
            }
            .ok_or_else(|| SimError::Invalid("vision needs a sensor".into()))?)
        };
        let localizer = if localizes {
            let index = vision_sensor()?;
            let cal = vision_calibration(scenario, index)?;
            Some(Localizer {
                sensor: index,
                localizer: FloorLocalizer::new(scenario.vision.localization.clone(), &cal)?,
            })
        } else {
            None
        };
        let vision = if scenario.control.kind.uses_vision() && scenario.experiment.is_none() {
            let index = vision_sensor()?;
            let cal = vision_calibration(scenario, index)?;
            let detector = FreeSpaceDetector::new(scenario.vision.freespace.clone(), &cal)?;
            let range_mm = *detector.template().edges_mm().last().expect("edges");
            Some(Vision {
                sensor: index,
                detector,
                range_mm,
                mount_mm: cal.mount_mm,
            })
        } else {
            None
        };
        let mut movers = Vec::new();
        for o in &scenario.other_robots {
            let drive = AccelLimitedDrive::new(o.accel_limit_mm_s2, 10.0)?;
            movers.push(Mover {
                waypoints: o
                    .waypoints_mm
                    .iter()
                    .map(|w| Point2::new(w[0], w[1]))
                    .collect(),
                next: 0,
                cycle: o.cycle,
                controller: GoToGoal::new(o.max_speed_mm_s, drive)?,
            });
        }
        let needs_images = !scenario.robot.sensors.is_empty()
            && (vision.is_some() || localizer.is_some() || options.save_frames_every.is_some());
        let eyes = if needs_images {
            let renderer = Renderer::new(options.renderer, notice)?;
            let mut sensors = Vec::new();
            for (i, spec) in scenario.robot.sensors.iter().enumerate() {
                sensors.push((
                    spec.build()?,
                    SensorNoise::new(sensor_noise_seed(scenario.seed, i)),
                ));
            }
            Some(Eyes { renderer, sensors })
        } else {
            None
        };
        let tracker = PoseTracker::new(
            scenario.robot.start.isometry(),
            &scenario.odometry,
            scenario.control.pose_source,
            scenario.control.localization_gain,
            scenario.seed,
        );
        Ok(Self {
            scenario: scenario.clone(),
            brain,
            vision,
            localizer,
            tracker,
            targets: scenario.goal.as_ref().map_or(Vec::new(), |g| g.targets()),
            next_target: 0,
            pose_errors_mm: Vec::new(),
            eyes,
            options: options.clone(),
            world,
            other_paths: vec![Vec::new(); movers.len()],
            movers,
            cycle: 0,
            time_to_goal_s: None,
            trajectory: Vec::new(),
            freespace_errors_mm: Vec::new(),
            last_freespace: None,
        })
    }

    /// The world being simulated.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// Control cycles run so far.
    pub fn cycle(&self) -> u64 {
        self.cycle
    }

    /// The free space detected in the last cycle, if the controller uses vision.
    pub fn last_freespace(&self) -> Option<&FreeSpace> {
        self.last_freespace.as_ref()
    }

    /// Whether the run is over: time is up, or the goal is reached and the run stops there.
    pub fn finished(&self) -> bool {
        self.cycle >= self.scenario.max_cycles()
            || (self.scenario.run.stop_at_goal && self.time_to_goal_s.is_some())
    }

    /// Name of the renderer in use, if the run renders.
    pub fn renderer_name(&self) -> Option<&str> {
        self.eyes.as_ref().map(|e| e.renderer.name())
    }

    /// Renders every sensor of the robot under test at its current pose (with noise).
    fn sense(&mut self) -> Result<Vec<image::RgbaImage>, RunError> {
        let Some(eyes) = &mut self.eyes else {
            return Ok(Vec::new());
        };
        let pose = self.world.robot_state(0).pose;
        let scene = Scene::of_world(&self.world);
        let mut frames = Vec::with_capacity(eyes.sensors.len());
        for (sensor, noise) in eyes.sensors.iter_mut() {
            frames.push(eyes.renderer.render(&scene, sensor, &pose, Some(noise))?);
        }
        Ok(frames)
    }

    fn save_frames(&self, frames: &[image::RgbaImage]) -> Result<(), RunError> {
        let (Some(every), Some(dir), Some(eyes)) = (
            self.options.save_frames_every,
            &self.options.frames_dir,
            &self.eyes,
        ) else {
            return Ok(());
        };
        if every == 0 || !self.cycle.is_multiple_of(every) {
            return Ok(());
        }
        for (img, (sensor, _)) in frames.iter().zip(&eyes.sensors) {
            let path = dir.join(format!("{}_{:06}.png", sensor.name, self.cycle));
            img.save(&path)
                .map_err(|source| RunError::Frame { path, source })?;
        }
        Ok(())
    }

    /// Compares the detected free distances with the world's, direction by direction (truth
    /// clipped at the template's range).
    fn score_freespace(&mut self, fs: &FreeSpace, range_mm: f64, mount: [f64; 2]) {
        let pose = self.world.robot_state(0).pose;
        let axis = pose * Point2::new(mount[0], mount[1]);
        let heading = pose.rotation.angle();
        for (a, free) in fs.direction_rad.iter().zip(&fs.free_mm) {
            let dir = Vector2::new((heading + a).cos(), (heading + a).sin());
            let truth = self
                .world
                .ray_cast_mm(axis, dir, range_mm, Some(0))
                .unwrap_or(range_mm);
            self.freespace_errors_mm.push((free - truth).abs());
        }
    }

    /// One control cycle: observe, choose commands, record, advance the world one period.
    pub fn step(&mut self) -> Result<(), RunError> {
        let frames = self.sense()?;
        self.save_frames(&frames)?;
        let t = self.world.time_s();
        let state = self.world.robot_state(0);
        let heading = state.pose.rotation.angle();

        let freespace = match &mut self.vision {
            Some(v) => {
                let fs = v.detector.detect(&frames[v.sensor])?;
                Some((fs, v.range_mm, v.mount_mm))
            }
            None => None,
        };
        if let Some((fs, range, mount)) = &freespace {
            self.score_freespace(fs, *range, *mount);
        }

        if let Some(l) = &mut self.localizer {
            let prior = self.tracker.estimate();
            if let Localization::Localized(e) =
                l.localizer.locate(&frames[l.sensor], Some(&prior))?
            {
                self.tracker.correct(&e);
            }
        }
        let target = self.targets.get(self.next_target).copied();
        let goal_body = target.map(|g| self.tracker.to_body(g));
        let v_body = self.tracker.velocity_body_mm_s();
        let body_command =
            |v: Vector2<f64>| VelocityCommand::translate(Rotation2::new(heading) * v);
        let points: Vec<Vector2<f64>> = freespace.as_ref().map_or(Vec::new(), |(fs, _, _)| {
            fs.obstacle_points.iter().map(|p| p.coords).collect()
        });
        let surroundings = freespace.as_ref().map(|(fs, range, _)| Surroundings {
            direction_rad: &fs.direction_rad,
            free_mm: &fs.free_mm,
            range_mm: *range,
            obstacle_points: &points,
        });
        let command = match (&self.brain, &surroundings, goal_body) {
            (Brain::Truth(c), _, _) => match target {
                Some(g) => c.command(state.pose.translation.vector, g.coords),
                None => VelocityCommand::STOP,
            },
            (Brain::GoalDirection(c), Some(s), Some(goal)) => {
                body_command(c.decide(s, goal).v_mm_s)
            }
            (Brain::VelocityAware(c), Some(s), Some(goal)) => {
                body_command(c.decide(s, goal, v_body).v_mm_s)
            }
            _ => VelocityCommand::STOP,
        };
        self.world.set_command(0, command);
        self.last_freespace = freespace.map(|(fs, _, _)| fs);

        for (k, m) in self.movers.iter_mut().enumerate() {
            let p = Point2::from(self.world.robot_state(k + 1).pose.translation.vector);
            self.other_paths[k].push(p);
            if m.next < m.waypoints.len() && (m.waypoints[m.next] - p).norm() < 20.0 {
                m.next += 1;
                if m.cycle && m.next == m.waypoints.len() {
                    m.next = 0;
                }
            }
            let cmd = match m.waypoints.get(m.next) {
                Some(w) => m.controller.command(p.coords, w.coords),
                None => VelocityCommand::STOP,
            };
            self.world.set_command(k + 1, cmd);
        }
        let row = self.row(t, command);
        if let (Some(x), Some(y)) = (row.est_x_mm, row.est_y_mm) {
            self.pose_errors_mm.push((x - row.x_mm).hypot(y - row.y_mm));
        }
        self.trajectory.push(row);

        let dt = self.scenario.run.control_period_s;
        self.world.advance(dt);
        self.cycle += 1;
        let after = self.world.robot_state(0);
        self.tracker.measure(
            after.velocity_mm_s,
            after.pose.rotation.angle(),
            after.omega_rad_s,
            dt,
        );
        if let (Some(g), Some(t)) = (&self.scenario.goal, self.targets.get(self.next_target)) {
            let p = after.pose.translation.vector;
            if (p - t.coords).norm() <= g.tolerance_mm {
                self.next_target += 1;
                if self.next_target == self.targets.len() {
                    self.time_to_goal_s = Some(self.world.time_s());
                }
            }
        }
        Ok(())
    }

    /// Experiment mode (E2): carries the robot to each place, localizes it there in
    /// `frames_per_place` frames with fresh noise, and scores the estimates per place.
    pub fn run_places(
        &mut self,
        mut progress: impl FnMut(u64, u64),
    ) -> Result<Vec<PlaceResult>, RunError> {
        let Some(exp) = self.scenario.experiment.clone() else {
            return Ok(Vec::new());
        };
        let total = exp.places.len() as u64 * exp.frames_per_place as u64;
        let dt = self.scenario.run.control_period_s;
        let mut results = Vec::new();
        for place in &exp.places {
            let truth = place.isometry();
            self.world.place_robot(0, truth);
            let (mut sq_pos, mut sq_head, mut n_ok, mut ambiguous, mut missing) =
                (0.0, 0.0, 0usize, 0usize, 0usize);
            for _ in 0..exp.frames_per_place {
                let frames = self.sense()?;
                self.save_frames(&frames)?;
                let t = self.world.time_s();
                let mut row = self.row(t, VelocityCommand::STOP);
                let l = self.localizer.as_mut().expect("experiment mode localizes");
                match l.localizer.locate(&frames[l.sensor], None)? {
                    Localization::Localized(e) => {
                        let err = |q: &nalgebra::Isometry2<f64>| {
                            (q.translation.vector - truth.translation.vector).norm()
                        };
                        if err(&e.alternative) < err(&e.pose) {
                            ambiguous += 1;
                        }
                        let dh = (e.pose.rotation.angle() - truth.rotation.angle())
                            .sin()
                            .atan2((e.pose.rotation.angle() - truth.rotation.angle()).cos());
                        sq_pos += err(&e.pose).powi(2);
                        sq_head += dh.powi(2);
                        n_ok += 1;
                        row.est_x_mm = Some(e.pose.translation.x);
                        row.est_y_mm = Some(e.pose.translation.y);
                        row.est_theta_rad = Some(e.pose.rotation.angle());
                        self.pose_errors_mm.push(err(&e.pose));
                    }
                    Localization::NotLocalized(_) => missing += 1,
                }
                self.trajectory.push(row);
                self.world.advance(dt);
                self.cycle += 1;
                progress(self.cycle, total);
            }
            let rms = |sq: f64| {
                if n_ok > 0 {
                    (sq / n_ok as f64).sqrt()
                } else {
                    f64::NAN
                }
            };
            results.push(PlaceResult {
                true_pose: [place.x_mm, place.y_mm, place.heading_deg],
                rms_position_mm: rms(sq_pos),
                rms_heading_deg: rms(sq_head).to_degrees(),
                ambiguity_errors: ambiguous,
                frames: exp.frames_per_place as usize,
                not_localized: missing,
            });
        }
        Ok(results)
    }

    /// The trajectory row of the current state with `command`.
    fn row(&self, t: f64, command: VelocityCommand) -> TrajectoryRow {
        let s = self.world.robot_state(0);
        let est = (self.scenario.control.kind.uses_vision() && self.scenario.experiment.is_none())
            .then(|| self.tracker.estimate());
        TrajectoryRow {
            t_s: t,
            x_mm: s.pose.translation.x,
            y_mm: s.pose.translation.y,
            theta_rad: s.pose.rotation.angle(),
            vx_mm_s: s.velocity_mm_s.x,
            vy_mm_s: s.velocity_mm_s.y,
            cmd_vx_mm_s: command.v_mm_s.x,
            cmd_vy_mm_s: command.v_mm_s.y,
            est_x_mm: est.map(|e| e.translation.x),
            est_y_mm: est.map(|e| e.translation.y),
            est_theta_rad: est.map(|e| e.rotation.angle()),
        }
    }

    /// Ends the run: the summary and everything recorded.
    pub fn finish(mut self, wall_time_s: f64) -> RunOutput {
        // The final state closes the trajectory (driving runs only).
        if self.scenario.experiment.is_none() {
            let last = self.row(self.world.time_s(), self.world.command(0));
            self.trajectory.push(last);
        }
        for (k, path) in self.other_paths.iter_mut().enumerate() {
            path.push(Point2::from(
                self.world.robot_state(k + 1).pose.translation.vector,
            ));
        }
        let stats = self.world.stats(0);
        let corner = self.scenario.metrics.corner.as_ref().map(|c| {
            let a = c.leg1_heading_deg.to_radians();
            corner_metrics(
                &self.trajectory,
                Vector2::from(c.k_mm),
                Vector2::new(a.cos(), a.sin()),
            )
        });
        let summary = Summary {
            scenario: self.scenario.name.clone(),
            seed: self.scenario.seed,
            controller: controller_name(self.scenario.control.kind),
            cycles: self.cycle,
            sim_time_s: self.world.time_s(),
            wall_time_s,
            cycles_per_s: if wall_time_s > 0.0 {
                self.cycle as f64 / wall_time_s
            } else {
                0.0
            },
            wall_contacts: stats.contacts,
            peak_speed_mm_s: stats.peak_speed_mm_s,
            peak_accel_mm_s2: stats.peak_accel_mm_s2,
            reached_goal: self.time_to_goal_s.is_some(),
            time_to_goal_s: self.time_to_goal_s,
            min_clearance_mm: stats.min_clearance_mm,
            path_length_mm: stats.path_length_mm,
            renderer: self.eyes.as_ref().map(|e| e.renderer.name().to_string()),
            turn_onset_mm: corner.and_then(|c| c.turn_onset_mm),
            overshoot_mm: corner.map(|c| c.overshoot_mm),
            freespace_error_mm: median(&self.freespace_errors_mm),
            pose_error_mm: median(&self.pose_errors_mm),
            targets_reached: (self.targets.len() > 1).then_some(self.next_target),
            localization_fixes: self.localizer.as_ref().map(|_| self.tracker.fixes().0),
            places: None,
        };
        RunOutput {
            summary,
            trajectory: self.trajectory,
            other_paths: self.other_paths,
        }
    }
}

/// Runs a validated scenario to its end, calling `progress(cycle, max_cycles)` after each cycle.
/// The summary's `wall_time_s` covers the whole run, set-up included (calibration tracing,
/// opening the renderer); its `cycles_per_s` covers the control cycles alone.
pub fn run_scenario(
    scenario: &Scenario,
    options: &RunOptions,
    notice: impl FnOnce(&str),
    mut progress: impl FnMut(u64, u64),
) -> Result<RunOutput, RunError> {
    let start = Instant::now();
    if let Some(dir) = &options.frames_dir {
        std::fs::create_dir_all(dir).map_err(|e| RunError::Frame {
            path: dir.clone(),
            source: image::ImageError::IoError(e),
        })?;
    }
    let mut sim = Simulation::new(scenario, options, notice)?;
    let loop_start = Instant::now();
    let places = if scenario.experiment.is_some() {
        Some(sim.run_places(progress)?)
    } else {
        let max = scenario.max_cycles();
        while !sim.finished() {
            sim.step()?;
            progress(sim.cycle(), max);
        }
        None
    };
    let loop_s = loop_start.elapsed().as_secs_f64();
    let mut out = sim.finish(start.elapsed().as_secs_f64());
    out.summary.cycles_per_s = if loop_s > 0.0 {
        out.summary.cycles as f64 / loop_s
    } else {
        0.0
    };
    out.summary.places = places;
    Ok(out)
}

/// Renders what sensor `sensor` of the robot under test sees when the robot stands at `pose`
/// (the scenario's start when `None`) and every other robot at its start, with the sensor's
/// noise drawn as the first frame of a run would be, or clean when `noise` is false.
pub fn render_snapshot(
    scenario: &Scenario,
    renderer: &mut Renderer,
    sensor: Option<&str>,
    pose: Option<nalgebra::Isometry2<f64>>,
    noise: bool,
) -> Result<image::RgbaImage, RunError> {
    let index = match sensor {
        Some(n) => scenario.robot.sensors.iter().position(|s| s.name == n),
        None => (!scenario.robot.sensors.is_empty()).then_some(0),
    }
    .ok_or_else(|| {
        SimError::Invalid(match sensor {
            Some(n) => format!(
                "scenario {:?} has no sensor {n:?} (it has: {})",
                scenario.name,
                scenario
                    .robot
                    .sensors
                    .iter()
                    .map(|s| s.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            None => format!("scenario {:?} has no [[robot.sensors]]", scenario.name),
        })
    })?;
    let mut bodies = scenario.robot_bodies();
    if let Some(p) = pose {
        bodies[0].start = p;
    }
    let world = World::new(&scenario.world, &bodies, scenario.run.physics_step_s)?;
    let spec = &scenario.robot.sensors[index];
    let sensor = spec.build()?;
    let scene = Scene::of_world(&world);
    let mut noise_source = noise.then(|| SensorNoise::new(sensor_noise_seed(scenario.seed, index)));
    Ok(renderer.render(
        &scene,
        &sensor,
        &world.robot_state(0).pose,
        noise_source.as_mut(),
    )?)
}
