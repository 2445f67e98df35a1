//! The closed loop on the simulator's side: render the robot's cameras, hand its software what
//! its sensors give, apply its commands, step the world, and record the truth beside what the
//! robot believes.

use super::cameras::{Cameras, sensor_noise_seed};
use super::column_calibration::calibrate_columns;
use super::error::RunError;
use super::observer::{CycleView, ObserverHandle};
use super::odometry::WheelOdometry;
use super::pilot::Pilot;
use super::record::{Summary, TrajectoryRow};
use super::score::TruthScore;
use crate::scenario::calibrate::calibrate_sensor;
use crate::scenario::{PilotChoice, Scenario};
use nalgebra::{Isometry2, Point2, Rotation2, Vector2};
use omniloop_control::{AccelLimitedDrive, VelocityCommand};
use omniloop_robot::{
    ActuatorState, Estimates, FixOutcome, Frame, Observation, OdometryReading, Robot, RobotConfig,
    RobotError, RobotSoftware,
};
use omniloop_sim::render::BatchHandle;
use omniloop_sim::{Renderer, RendererChoice, Scene, SensorNoise, SimError, World};
use omniloop_vision::RadialCalibration;
use omniloop_vision::resection::ColumnCalibration;
use std::path::PathBuf;

/// How to run a scenario (what the command line adds to the scenario file).
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Which renderer traces the cameras' images.
    pub renderer: RendererChoice,
    /// Save every camera's image every this many cycles (with `frames_dir`).
    pub save_frames_every: Option<u64>,
    /// Where saved frames go.
    pub frames_dir: Option<PathBuf>,
    /// A GPU shared with other runs, its frames traced in batches (overrides `renderer`).
    pub shared_gpu: Option<BatchHandle>,
    /// The experimenter takes frames of vision's camera (the camera is rendered and calibrated
    /// whatever the robot's software reads); the scenario's experiment sets it.
    pub takes_frames: bool,
    /// See every cycle after it is recorded (a log, an animation); they cannot change the run.
    pub observers: Vec<ObserverHandle>,
}

/// Everything a run produced.
#[derive(Debug, Clone)]
pub struct RunOutput {
    /// Metrics.
    pub summary: Summary,
    /// One row a control cycle (and the final state, for driving runs).
    pub trajectory: Vec<TrajectoryRow>,
    /// What the robot believed, one record a control cycle.
    pub estimates: Vec<Estimates>,
    /// The paths of the other robots, one point a control cycle.
    pub other_paths: Vec<Vec<Point2<f64>>>,
    /// Files of the experiment's own (tables, figures), written beside the run's.
    pub files: Vec<OutputFile>,
    /// The map the robot's software built, when it builds one.
    pub map: Option<omniloop_robot::MapSnapshot>,
}

/// A file an experiment produced: its name in the output folder and its contents.
#[derive(Debug, Clone)]
pub struct OutputFile {
    /// File name (`selfloc_map.csv`).
    pub name: String,
    /// Contents.
    pub bytes: Vec<u8>,
}

/// The calibrations of the cameras the robot's vision uses: the scenario's file, or the
/// camera's traced map.
fn calibrations(
    scenario: &Scenario,
    takes_frames: bool,
) -> Result<Vec<RadialCalibration>, RunError> {
    if !(scenario.needs_calibration() || takes_frames) {
        return Ok(Vec::new());
    }
    let index = scenario.vision_sensor_index().map_err(SimError::Invalid)?;
    let spec = &scenario.robot.sensors[index];
    let mut cal = match &scenario.vision.calibration_file {
        Some(path) => RadialCalibration::load(path)?,
        None => calibrate_sensor(spec)?,
    };
    // The file is this camera's calibration, whatever name it was written under.
    cal.sensor = spec.name.clone();
    Ok(vec![cal])
}

/// The column calibrations of the pinhole camera the robot resects with, measured from images
/// of the calibration target.
fn columns(scenario: &Scenario) -> Result<Vec<ColumnCalibration>, RunError> {
    if !scenario.needs_columns() {
        return Ok(Vec::new());
    }
    let index = scenario.vision_sensor_index().map_err(SimError::Invalid)?;
    Ok(vec![calibrate_columns(
        &scenario.robot.sensors[index],
        scenario.seed,
    )?])
}

/// A scenario being run, one control cycle at a time.
pub struct Simulation {
    scenario: Scenario,
    world: World,
    cameras: Option<Cameras>,
    calibrations: Vec<RadialCalibration>,
    odometry: WheelOdometry,
    robot: Box<dyn RobotSoftware>,
    pilot: Option<Pilot>,
    others: Vec<Pilot>,
    truth: TruthScore,
    cycle: u64,
    trajectory: Vec<TrajectoryRow>,
    estimates: Vec<Estimates>,
    other_paths: Vec<Vec<Point2<f64>>>,
    options: RunOptions,
    last_odometry: Option<OdometryReading>,
    /// Commands on their way to the drive: when each is due, and the command.
    commands: std::collections::VecDeque<(f64, VelocityCommand)>,
}

impl Simulation {
    /// Builds the world, the built-in robot software and the cameras of a validated scenario.
    /// `notice` receives one-line messages for the user (e.g. the renderer's choice).
    pub fn new(
        scenario: &Scenario,
        options: &RunOptions,
        notice: impl FnOnce(&str),
    ) -> Result<Self, RunError> {
        Self::with_software(scenario, options, builtin_software, notice)
    }

    /// Builds the world and the cameras of a validated scenario, with the robot's software
    /// that `software` builds from what the robot is told ([`RobotConfig`]: its start, body,
    /// cameras and their calibrations, goal, map; never the world).
    pub fn with_software(
        scenario: &Scenario,
        options: &RunOptions,
        software: impl FnOnce(&RobotConfig) -> Result<Box<dyn RobotSoftware>, RobotError>,
        notice: impl FnOnce(&str),
    ) -> Result<Self, RunError> {
        let world = World::new(
            &scenario.world,
            &scenario.robot_bodies(),
            scenario.run.physics_step_s,
        )?;
        let calibrations = calibrations(scenario, options.takes_frames)?;
        let robot = software(&scenario.robot_config(calibrations.clone(), columns(scenario)?))?;
        let r = &scenario.robot;
        let pilot = match (&scenario.goal, scenario.run.pilot) {
            (Some(g), PilotChoice::Truth) => Some(Pilot::new(
                g.targets(),
                g.tolerance_mm,
                false,
                r.max_speed_mm_s,
                AccelLimitedDrive::new(r.accel_limit_mm_s2, r.angular_accel_limit_rad_s2)?,
            )?),
            _ => None,
        };
        let mut others = Vec::new();
        for o in &scenario.other_robots {
            let waypoints = o.waypoints_mm.iter().map(|w| Point2::new(w[0], w[1]));
            let drive = AccelLimitedDrive::new(o.accel_limit_mm_s2, 10.0)?;
            others.push(Pilot::new(
                waypoints.collect(),
                20.0,
                o.cycle,
                o.max_speed_mm_s,
                drive,
            )?);
        }
        let cameras = Cameras::open(
            scenario,
            &robot.cameras(),
            options.save_frames_every.is_some() || options.takes_frames,
            options.renderer,
            options.shared_gpu.as_ref(),
            notice,
        )?;
        for o in &options.observers {
            o.with(|o| o.start(&world));
        }
        Ok(Self {
            scenario: scenario.clone(),
            world,
            cameras,
            calibrations,
            odometry: WheelOdometry::new(&scenario.odometry, scenario.seed),
            robot,
            pilot,
            other_paths: vec![Vec::new(); others.len()],
            others,
            truth: TruthScore::new(scenario.goal.as_ref()),
            cycle: 0,
            trajectory: Vec::new(),
            estimates: Vec::new(),
            options: options.clone(),
            last_odometry: None,
            commands: std::collections::VecDeque::new(),
        })
    }

    /// The world being simulated.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The scenario being run.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// The robot's software.
    pub fn robot_mut(&mut self) -> &mut dyn RobotSoftware {
        self.robot.as_mut()
    }

    /// Control cycles run so far.
    pub fn cycle(&self) -> u64 {
        self.cycle
    }

    /// The trajectory recorded so far, a row a cycle (and the final state once recorded).
    pub fn trajectory(&self) -> &[TrajectoryRow] {
        &self.trajectory
    }

    /// What the robot believed, a record a cycle so far.
    pub fn estimates(&self) -> &[Estimates] {
        &self.estimates
    }

    /// What the robot believed in the last cycle.
    pub fn last_estimates(&self) -> Option<&Estimates> {
        self.estimates.last()
    }

    /// The true pose of the robot under test when the last cycle's frames were taken.
    pub fn last_truth_pose(&self) -> Option<Isometry2<f64>> {
        self.trajectory
            .last()
            .map(|r| Isometry2::new(Vector2::new(r.x_mm, r.y_mm), r.theta_rad))
    }

    /// Whether the run is over: time is up, or the goal is reached and the run stops there.
    pub fn finished(&self) -> bool {
        self.cycle >= self.scenario.max_cycles()
            || (self.scenario.run.stop_at_goal && self.truth.time_to_goal_s().is_some())
    }

    /// The calibration of the camera the robot's vision uses, when its software uses one.
    pub fn vision_calibration(&self) -> Option<&RadialCalibration> {
        self.calibrations.first()
    }

    /// Renders the camera the robot's vision uses as it sees the world now, with its noise (a
    /// frame of its own, as an experimenter would take one): `None` when no camera is rendered.
    pub fn vision_frame(&mut self) -> Result<Option<&image::RgbaImage>, RunError> {
        let index = self.scenario.vision_sensor_index().ok();
        let name = index.map(|i| self.scenario.robot.sensors[i].name.as_str());
        match (&mut self.cameras, name) {
            (Some(c), Some(name)) => {
                c.capture(&self.world)?;
                Ok(c.image(name))
            }
            _ => Ok(None),
        }
    }

    /// Puts the robot under test at `pose`, at rest (an experimenter carrying it there).
    pub fn place_robot(&mut self, pose: Isometry2<f64>) {
        self.world.place_robot(0, pose);
    }

    /// One control cycle: the cameras see ([`Simulation::sense`]), then the robot's software
    /// decides and the world moves on ([`Simulation::act`]).
    pub fn step(&mut self) -> Result<(), RunError> {
        self.sense()?;
        self.act()
    }

    /// The first half of a control cycle: renders the cameras the robot's software reads now
    /// (every camera when frames are saved) as the world is at the cycle's start, and saves
    /// them when asked. [`Simulation::frames`] gives them until the next sense.
    pub fn sense(&mut self) -> Result<(), RunError> {
        let Some(c) = &mut self.cameras else {
            return Ok(());
        };
        let wanted = self.robot.cameras_now();
        let saving = self.options.save_frames_every.is_some();
        c.capture_some(&self.world, (!saving).then_some(wanted.as_slice()))?;
        if let (Some(every), Some(dir)) = (self.options.save_frames_every, &self.options.frames_dir)
            && every > 0
            && self.cycle.is_multiple_of(every)
        {
            c.save(dir, self.cycle)?;
        }
        Ok(())
    }

    /// The frames the software gets after the last [`Simulation::sense`], stamped with the
    /// time they were taken (none without cameras).
    pub fn frames(&self) -> Vec<Frame<'_>> {
        self.cameras
            .as_ref()
            .map(|c| c.frames())
            .unwrap_or_default()
    }

    /// The wheel odometry's reading at the end of the last cycle, as the robot's software got
    /// it (none before the first cycle).
    pub fn last_odometry(&self) -> Option<OdometryReading> {
        self.last_odometry
    }

    /// The state of the robot's actuators (its pan units) now.
    pub fn actuator_state(&self) -> Vec<ActuatorState> {
        self.cameras
            .as_ref()
            .map(|c| c.actuator_state())
            .unwrap_or_default()
    }

    /// The second half of a control cycle: the robot's software decides on the frames of the
    /// last [`Simulation::sense`], its commands are applied and recorded, the world advances
    /// one period, the wheels report.
    pub fn act(&mut self) -> Result<(), RunError> {
        let t = self.world.time_s();
        let cameras = self.cameras.as_ref();
        let frames = cameras.map(|c| c.frames()).unwrap_or_default();
        let actuators = cameras.map(|c| c.actuator_state()).unwrap_or_default();
        let out = self.robot.cycle(&Observation {
            t_s: t,
            frames: &frames,
            actuators: &actuators,
        })?;
        drop(frames);
        let state = self.world.robot_state(0);
        let (command, heading_for) = match &mut self.pilot {
            Some(p) => (
                p.command(Point2::from(state.pose.translation.vector)),
                Some(p.index()),
            ),
            None => (
                VelocityCommand {
                    v_mm_s: Rotation2::new(state.pose.rotation.angle()) * out.command.v_mm_s,
                    omega_rad_s: out.command.omega_rad_s,
                },
                out.estimates.target,
            ),
        };
        let latency = self.scenario.robot.timing.command_latency_s;
        self.commands.push_back((t + latency, command));
        if let Some(c) = &mut self.cameras {
            c.command(&out.actuators)?;
        }
        if let Some(fs) = &out.estimates.freespace {
            let mount = self.vision_mount_mm();
            self.truth.freespace(&self.world, &state.pose, mount, fs);
        }
        self.drive_others();
        self.record(t, command, out.estimates);
        self.observe();

        let dt = self.scenario.run.control_period_s;
        self.advance_applying_commands(t + dt);
        if let Some(c) = &mut self.cameras {
            c.advance(dt);
        }
        self.cycle += 1;
        let after = self.world.robot_state(0);
        let reading = self.odometry.read(&after, dt);
        self.robot.odometry(&reading);
        self.last_odometry = Some(reading);
        let p = Point2::from(after.pose.translation.vector);
        self.truth.targets(p, heading_for, self.world.time_s());
        Ok(())
    }

    /// Moves the world on to `end_s`, each queued command reaching the drive when it is due
    /// (`[robot.timing] command_latency_s` after the software gave it; at once without one).
    fn advance_applying_commands(&mut self, end_s: f64) {
        let half_step = 0.5 * self.scenario.run.physics_step_s;
        loop {
            let now = self.world.time_s();
            while let Some(&(due, command)) = self.commands.front() {
                if due > now + half_step {
                    break;
                }
                self.world.set_command(0, command);
                self.commands.pop_front();
            }
            match self.commands.front() {
                Some(&(due, _)) if due < end_s - half_step => self.world.advance(due - now),
                _ => {
                    self.world.advance(end_s - now);
                    return;
                }
            }
        }
    }

    /// Where the axis of the camera vision uses sits on the robot.
    fn vision_mount_mm(&self) -> [f64; 2] {
        self.scenario
            .vision_sensor_index()
            .map_or([0.0, 0.0], |i| self.scenario.robot.sensors[i].mount_mm)
    }

    /// The other robots drive on, each by its pilot on its true position.
    fn drive_others(&mut self) {
        for (k, pilot) in self.others.iter_mut().enumerate() {
            let p = Point2::from(self.world.robot_state(k + 1).pose.translation.vector);
            self.other_paths[k].push(p);
            let cmd = pilot.command(p);
            self.world.set_command(k + 1, cmd);
        }
    }

    /// Records the cycle: the trajectory row (truth, command, estimated pose) and the robot's
    /// estimates, and scores the pose estimate.
    fn record(&mut self, t: f64, command: VelocityCommand, estimates: Estimates) {
        let row = self.row(t, command, estimates.pose);
        if let Some(est) = &estimates.pose {
            let truth = Isometry2::new(Vector2::new(row.x_mm, row.y_mm), row.theta_rad);
            self.truth.checkpoint(est, &truth);
        }
        if let (Some(x), Some(y)) = (row.est_x_mm, row.est_y_mm) {
            self.truth
                .pose(Point2::new(x, y), Point2::new(row.x_mm, row.y_mm));
        }
        self.trajectory.push(row);
        self.estimates.push(estimates);
    }

    /// Shows the cycle just recorded to the observers.
    fn observe(&self) {
        let (Some(row), Some(estimates)) = (self.trajectory.last(), self.estimates.last()) else {
            return;
        };
        if self.options.observers.is_empty() {
            return;
        }
        let frames = self.frames();
        let view = CycleView {
            cycle: self.cycle,
            row,
            estimates,
            frames: &frames,
        };
        for o in &self.options.observers {
            o.with(|o| o.cycle(&view));
        }
    }

    /// Closes the trajectory with the final state (driving runs).
    pub fn record_final_state(&mut self) {
        let row = self.row(
            self.world.time_s(),
            self.world.command(0),
            self.robot.estimate(),
        );
        self.trajectory.push(row);
    }

    /// The trajectory row of the current state with `command` and the estimate.
    fn row(&self, t: f64, command: VelocityCommand, est: Option<Isometry2<f64>>) -> TrajectoryRow {
        let s = self.world.robot_state(0);
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

    /// The truth now: the robot's true pose and velocity, its contacts so far and whether
    /// it has reached the goal (the simulator's side, for scoring and recording only).
    pub fn truth(&self) -> Truth {
        let s = self.world.robot_state(0);
        Truth {
            t_s: self.world.time_s(),
            pose: s.pose,
            velocity_mm_s: s.velocity_mm_s,
            omega_rad_s: s.omega_rad_s,
            contacts: self.world.stats(0).contacts,
            reached_goal: self.truth.time_to_goal_s().is_some(),
            targets_reached: self.truth.targets_reached(),
        }
    }

    /// Ends the run: the summary of what the truth shows, and everything recorded.
    pub fn finish(mut self, wall_time_s: f64) -> RunOutput {
        let ends = self.other_robot_ends();
        for (path, end) in self.other_paths.iter_mut().zip(ends) {
            path.push(end);
        }
        RunOutput {
            summary: self.summary(wall_time_s),
            map: self.robot.map(),
            trajectory: self.trajectory,
            estimates: self.estimates,
            other_paths: self.other_paths,
            files: Vec::new(),
        }
    }

    /// What [`Simulation::finish`] would give now, the run going on (its records copied).
    pub fn output(&self, wall_time_s: f64) -> RunOutput {
        let mut other_paths = self.other_paths.clone();
        for (path, end) in other_paths.iter_mut().zip(self.other_robot_ends()) {
            path.push(end);
        }
        RunOutput {
            summary: self.summary(wall_time_s),
            map: self.robot.map(),
            trajectory: self.trajectory.clone(),
            estimates: self.estimates.clone(),
            other_paths,
            files: Vec::new(),
        }
    }

    /// Where the other robots are now.
    fn other_robot_ends(&self) -> Vec<Point2<f64>> {
        (0..self.others.len())
            .map(|k| Point2::from(self.world.robot_state(k + 1).pose.translation.vector))
            .collect()
    }

    /// The summary of what the truth shows so far.
    fn summary(&self, wall_time_s: f64) -> Summary {
        let stats = self.world.stats(0);
        let navigation = self
            .estimates
            .iter()
            .rev()
            .find_map(|e| e.navigation.as_ref());
        Summary {
            scenario: self.scenario.name.clone(),
            seed: self.scenario.seed,
            controller: match self.pilot {
                Some(_) => "truth_pilot".to_string(),
                None => self.robot.name(),
            },
            cycles: self.cycle,
            sim_time_s: self.world.time_s(),
            wall_time_s,
            cycles_per_s: 0.0,
            wall_contacts: stats.contacts,
            peak_speed_mm_s: stats.peak_speed_mm_s,
            peak_accel_mm_s2: stats.peak_accel_mm_s2,
            reached_goal: self.truth.time_to_goal_s().is_some(),
            time_to_goal_s: self.truth.time_to_goal_s(),
            min_clearance_mm: stats.min_clearance_mm,
            path_length_mm: stats.path_length_mm,
            renderer: self.cameras.as_ref().map(|c| c.renderer_name().to_string()),
            freespace_error_mm: self.truth.freespace_error_mm(),
            pose_error_mm: self.truth.pose_error_mm(),
            targets_reached: self.truth.targets_reached(),
            localization_fixes: localization_fixes(&self.estimates),
            checkpoint_heading_error_deg: self.truth.checkpoint_heading_errors_deg(),
            unreachable: navigation.map(|n| n.unreachable),
            watchdog_fired: navigation.map(|n| n.watchdog),
            experiment: serde_json::Map::new(),
        }
    }
}

/// The truth at a moment of a run: the simulator's side, never given to the robot's software.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Truth {
    /// Simulated time, s.
    pub t_s: f64,
    /// The robot's true pose (mm, rad).
    pub pose: Isometry2<f64>,
    /// Its true velocity in the world frame.
    pub velocity_mm_s: Vector2<f64>,
    /// Its true rotation rate.
    pub omega_rad_s: f64,
    /// How many times it started touching a wall, cube, pillar or robot so far.
    pub contacts: u32,
    /// Whether it has reached the goal (within the tolerance, after every waypoint).
    pub reached_goal: bool,
    /// How many of the goal's targets (waypoints, then the goal) it has reached.
    pub targets_reached: Option<usize>,
}

/// The built-in robot software of a configuration.
pub fn builtin_software(config: &RobotConfig) -> Result<Box<dyn RobotSoftware>, RobotError> {
    Ok(Box::new(Robot::new(config)?))
}

/// The fixes the estimator used (set or pulled its estimate by), when the robot localizes on
/// the floor region (its `floor_localization` stage reported a fix or why it found none).
fn localization_fixes(records: &[Estimates]) -> Option<usize> {
    const STAGE: &str = "floor_localization";
    let localizes = records.iter().any(|e| {
        e.fixes.iter().any(|f| f.source == STAGE) || e.not_found.iter().any(|n| n.source == STAGE)
    });
    let used = |e: &Estimates| {
        e.fixes
            .iter()
            .filter(|f| matches!(f.outcome, FixOutcome::Anchored | FixOutcome::Used))
            .count()
    };
    localizes.then(|| records.iter().map(used).sum())
}

/// Renders what sensor `sensor` of the robot under test sees when the robot stands at `pose`
/// (the scenario's start when `None`) and every other robot at its start, with the sensor's
/// noise drawn as the first frame of a run would be, or clean when `noise` is false.
pub fn render_snapshot(
    scenario: &Scenario,
    renderer: &mut Renderer,
    sensor: Option<&str>,
    pose: Option<Isometry2<f64>>,
    noise: bool,
) -> Result<image::RgbaImage, RunError> {
    let index = scenario
        .sensor_index(sensor)
        .map_err(|e| SimError::Invalid(format!("scenario {:?}: {e}", scenario.name)))?;
    let mut bodies = scenario.robot_bodies();
    if let Some(p) = pose {
        bodies[0].start = p;
    }
    let world = World::new(&scenario.world, &bodies, scenario.run.physics_step_s)?;
    let sensor = scenario.robot.sensors[index].build();
    let scene = Scene::of_world(&world);
    let mut noise_source = noise.then(|| SensorNoise::new(sensor_noise_seed(scenario.seed, index)));
    Ok(renderer.render(
        &scene,
        &sensor,
        &world.robot_state(0).pose,
        noise_source.as_mut(),
    )?)
}
