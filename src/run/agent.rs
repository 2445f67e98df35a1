//! One robot with software in the loop, on the simulator's side: its cameras, wheel odometry
//! and software, the commands on their way to its drive, and what was recorded of it (the
//! truth beside what it believed). The [`super::Simulation`] holds one for the robot of a
//! one-robot scenario and one for each robot of a team, and steps them together.

use super::cameras::Cameras;
use super::column_calibration::calibrate_columns;
use super::error::RunError;
use super::odometry::WheelOdometry;
use super::outcome::{GoalFigures, GoalOutcome, ProgressSample, made_progress, route_reachability};
use super::pilot::Pilot;
use super::record::{RobotSummary, TrajectoryRow};
use super::score::{FloorRegionScore, TruthScore};
use crate::scenario::calibrate::calibrate_sensor;
use crate::scenario::{PilotChoice, Scenario};
use nalgebra::{Isometry2, Point2, Rotation2, Vector2};
use omniloop_control::{AccelLimitedDrive, VelocityCommand};
use omniloop_robot::ActuatorCommand;
use omniloop_robot::perception::floor_localization;
use omniloop_robot::{
    ActuatorState, Estimates, FixOutcome, Frame, NavigationReport, Observation, OdometryReading,
    Outputs, RobotConfig, RobotError, RobotSoftware,
};
use omniloop_sim::render::BatchHandle;
use omniloop_sim::{
    BallCommand, Kick, Reachability, RendererChoice, RobotState, Scene, SimError, World,
};
use omniloop_vision::resection::ColumnCalibration;
use omniloop_vision::{FreeSpace, RadialCalibration};
use std::collections::VecDeque;
use std::path::Path;

/// What a robot's run recorded: its trajectory, its estimates, and (with the truth kept) each
/// cycle's floor-region score.
pub(crate) type Records = (
    Vec<TrajectoryRow>,
    Vec<Estimates>,
    Vec<Option<FloorRegionScore>>,
);

/// Builds a robot's software from what the robot is told.
pub type SoftwareBuilder<'a> =
    dyn FnMut(&RobotConfig) -> Result<Box<dyn RobotSoftware>, RobotError> + 'a;

/// How a robot's cameras are rendered: the renderer chosen, or a GPU shared through a batch
/// server; whether every camera is rendered (frames saved, an experimenter's).
pub struct CameraSetup<'a> {
    /// The renderer when no GPU is shared.
    pub renderer: RendererChoice,
    /// A shared GPU, its frames traced in batches.
    pub shared_gpu: Option<&'a BatchHandle>,
    /// Render every camera, whatever the software reads.
    pub all: bool,
    /// Trace each frame's truth beside it (depth, labels) and score the free space pixel by
    /// pixel.
    pub truth: bool,
}

/// A robot with software in the loop (see the module's documentation).
pub struct Agent {
    name: String,
    body: usize,
    scenario: Scenario,
    cameras: Option<Cameras>,
    calibrations: Vec<RadialCalibration>,
    odometry: WheelOdometry,
    software: Box<dyn RobotSoftware>,
    pilot: Option<Pilot>,
    truth: TruthScore,
    trajectory: Vec<TrajectoryRow>,
    estimates: Vec<Estimates>,
    /// With the truth kept: each recorded cycle's pixel-level score of the floor region, where
    /// the free-space stage judged that cycle's frame.
    floor_scores: Vec<Option<FloorRegionScore>>,
    last_odometry: Option<OdometryReading>,
    /// Commands on their way to the drive, kicker and dribbler: when each is due, and the
    /// commands.
    commands: VecDeque<(f64, VelocityCommand, BallCommand)>,
    /// The dribbler's speed its software last asked for, rpm.
    dribbler_rpm: f64,
    /// The target it headed for in the cycle being applied (its software's word, or the
    /// pilot's), checked on the truth once the world moved on.
    heading_for: Option<usize>,
    /// With a goal: whether its route can be driven on the true world (from its start).
    route: Option<Reachability>,
    /// With a goal: where it was and on which target, a sample a recorded cycle.
    progress: Vec<ProgressSample>,
}

impl Agent {
    /// Robot `body` of the world, named `name`, as `scenario` (its one-robot form) describes
    /// it, with the software `software` builds from what the robot is told.
    pub fn new(
        name: &str,
        body: usize,
        scenario: &Scenario,
        takes_frames: bool,
        cameras: CameraSetup<'_>,
        software: &mut SoftwareBuilder<'_>,
        notice: &mut dyn FnMut(&str),
    ) -> Result<Self, RunError> {
        let calibrations = calibrations(scenario, takes_frames)?;
        let mut config = scenario.robot_config(calibrations.clone(), columns(scenario)?);
        config.name = name.to_string();
        let software = software(&config)?;
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
        let route = match &scenario.goal {
            Some(g) => Some(route_reachability(
                &scenario.world,
                r.radius_mm,
                scenario.start().point(),
                g,
            )?),
            None => None,
        };
        let truth = cameras.truth;
        let mut cameras = Cameras::open(
            scenario,
            &software.cameras(),
            cameras.all || takes_frames,
            cameras.renderer,
            cameras.shared_gpu,
            |m| notice(m),
        )?;
        if let Some(c) = cameras.as_mut().filter(|_| truth) {
            c.keep_truth();
        }
        Ok(Self {
            name: name.to_string(),
            body,
            scenario: scenario.clone(),
            cameras,
            calibrations,
            odometry: WheelOdometry::new(&scenario.odometry, scenario.seed),
            software,
            pilot,
            truth: TruthScore::new(scenario.goal.as_ref()),
            trajectory: Vec::new(),
            estimates: Vec::new(),
            floor_scores: Vec::new(),
            last_odometry: None,
            commands: VecDeque::new(),
            dribbler_rpm: 0.0,
            heading_for: None,
            route,
            progress: Vec::new(),
        })
    }

    /// Its name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Its index among the world's robot bodies.
    pub fn body(&self) -> usize {
        self.body
    }

    /// The robot as a one-robot scenario (its robot, goal, vision, control, odometry, seed).
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// Its software.
    pub fn software(&self) -> &dyn RobotSoftware {
        self.software.as_ref()
    }

    /// Its software, to reach it between cycles.
    pub fn software_mut(&mut self) -> &mut dyn RobotSoftware {
        self.software.as_mut()
    }

    /// Its trajectory so far, a row a cycle (and the final state once recorded).
    pub fn trajectory(&self) -> &[TrajectoryRow] {
        &self.trajectory
    }

    /// What it believed, a record a cycle so far.
    pub fn estimates(&self) -> &[Estimates] {
        &self.estimates
    }

    /// The calibration of the camera its vision uses, when its software uses one.
    pub fn vision_calibration(&self) -> Option<&RadialCalibration> {
        self.calibrations.first()
    }

    /// Its cameras, when any is rendered.
    pub(crate) fn cameras_mut(&mut self) -> Option<&mut Cameras> {
        self.cameras.as_mut()
    }

    /// The renderer's name, when it has cameras.
    pub fn renderer_name(&self) -> Option<&str> {
        self.cameras.as_ref().map(Cameras::renderer_name)
    }

    /// The frames its software gets after the last sense, stamped with when they were taken.
    pub fn frames(&self) -> Vec<Frame<'_>> {
        self.cameras
            .as_ref()
            .map(|c| c.frames())
            .unwrap_or_default()
    }

    /// Its wheel odometry's reading at the end of the last cycle (none before the first).
    pub fn last_odometry(&self) -> Option<OdometryReading> {
        self.last_odometry
    }

    /// The state of its actuators in `world` now: its pan units, its kicker.
    pub fn actuator_state(&self, world: &World) -> Vec<ActuatorState> {
        let mut state = (self.cameras.as_ref())
            .map(|c| c.actuator_state())
            .unwrap_or_default();
        state.extend(self.kicker_state(world));
        state
    }

    /// Whether its goal is reached (on the truth).
    pub fn reached_goal(&self) -> bool {
        self.truth.time_to_goal_s().is_some()
    }

    /// Whether it has a goal.
    pub fn has_goal(&self) -> bool {
        self.scenario.goal.is_some()
    }

    /// Renders the cameras its software reads now (every camera with `all`) in `scene` at
    /// `now`, the robot in `state`; saves them to `save` (a folder and the cycle) when given.
    pub(crate) fn sense(
        &mut self,
        scene: &Scene,
        state: RobotState,
        now: f64,
        all: bool,
        save: Option<(&Path, u64)>,
    ) -> Result<(), RunError> {
        let Some(c) = &mut self.cameras else {
            return Ok(());
        };
        let wanted = self.software.cameras_now();
        c.capture_some(scene, state, now, (!all).then_some(wanted.as_slice()))?;
        if let Some((dir, cycle)) = save {
            c.save(dir, cycle)?;
        }
        Ok(())
    }

    /// Its kicker's state in `world` (its light barrier, its charge), when it has a kicker.
    pub(crate) fn kicker_state(&self, world: &World) -> Option<ActuatorState> {
        self.scenario
            .robot
            .kicker
            .as_ref()
            .map(|_| ActuatorState::Kicker {
                ball_in_dribbler: world.light_barrier(self.body),
                ready: world.kicker_ready(self.body),
            })
    }

    /// Its software decides on the frames of the last sense and the actuators' state (its pan
    /// units' and `kicker`), at time `t_s`.
    pub(crate) fn decide(
        &mut self,
        t_s: f64,
        kicker: Option<ActuatorState>,
    ) -> Result<Outputs, RunError> {
        let cameras = self.cameras.as_ref();
        let frames = cameras.map(|c| c.frames()).unwrap_or_default();
        let mut actuators = cameras.map(|c| c.actuator_state()).unwrap_or_default();
        actuators.extend(kicker);
        Ok(self.software.cycle(&Observation {
            t_s,
            frames: &frames,
            actuators: &actuators,
        })?)
    }

    /// Applies what its software decided at `t_s`: the command (turned into the world frame
    /// by the true heading, or the pilot's with `run.pilot = "truth"`) queued for the drive,
    /// the actuator commands to its pan units; scores the free space against `world` and
    /// records the cycle.
    pub(crate) fn apply(
        &mut self,
        world: &World,
        t_s: f64,
        mut out: Outputs,
    ) -> Result<(), RunError> {
        let state = world.robot_state(self.body);
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
        let ball = self.ball_command(&out.actuators)?;
        self.commands.push_back((t_s + latency, command, ball));
        if let Some(c) = &mut self.cameras {
            c.command(&out.actuators)?;
        }
        let floor = out
            .estimates
            .percepts
            .get_mut::<FreeSpace>()
            .and_then(|fs| {
                let mount = self.vision_mount_mm();
                let free_true = (self.truth).freespace(world, self.body, &state.pose, mount, fs);
                // The judged pixels are scored now and not kept in the record.
                let pixels = fs.pixels.take()?;
                let truth = self.vision_truth()?;
                Some(FloorRegionScore::of(&pixels, truth, free_true))
            });
        if let Some(score) = &floor {
            self.truth.floor_region(score);
        }
        if self.cameras.as_ref().is_some_and(Cameras::keeps_truth) {
            self.floor_scores.push(floor);
        }
        self.heading_for = heading_for;
        self.record(world, t_s, command, out.estimates);
        Ok(())
    }

    /// The kicker's and dribbler's part of the software's actuator commands, checked against
    /// the robot's kicker: a kick without one, over its limit or negative is an error.
    fn ball_command(&mut self, commands: &[ActuatorCommand]) -> Result<BallCommand, RunError> {
        let mut ball = BallCommand::default();
        for c in commands {
            let (kick, rpm) = match *c {
                ActuatorCommand::Kick {
                    speed_mm_s,
                    angle_rad,
                } => (
                    Some(Kick {
                        speed_mm_s,
                        angle_rad,
                    }),
                    None,
                ),
                ActuatorCommand::Dribble { rpm } => (None, Some(rpm)),
                _ => continue,
            };
            let Some(spec) = &self.scenario.robot.kicker else {
                return Err(RunError::Actuator(format!(
                    "the robot commanded {c:?}, but it has no kicker and dribbler \
                     ([robot.kicker])"
                )));
            };
            if let Some(why) = kick.and_then(|k| k.problem(spec)) {
                return Err(RunError::Actuator(why));
            }
            if let Some(rpm) = rpm {
                if !(rpm.is_finite() && rpm >= 0.0) {
                    return Err(RunError::Actuator(format!(
                        "dribbler speed {rpm} rpm must be a finite number >= 0"
                    )));
                }
                self.dribbler_rpm = rpm;
            }
            ball.kick = kick.or(ball.kick);
        }
        ball.dribbler_rpm = self.dribbler_rpm;
        Ok(ball)
    }

    /// The truth of the frame of vision's camera the software got this cycle, when kept.
    fn vision_truth(&self) -> Option<&omniloop_sim::render::TruthFrame> {
        let i = self.scenario.vision_sensor_index().ok()?;
        let name = &self.scenario.robot.sensors[i].name;
        self.cameras.as_ref()?.truth(name)
    }

    /// The truth of every frame its software got this cycle, by camera, when kept.
    pub fn truth_frames(&self) -> Vec<(&str, &omniloop_sim::render::TruthFrame)> {
        self.cameras
            .as_ref()
            .map(Cameras::truth_frames)
            .unwrap_or_default()
    }

    /// With the truth kept: each recorded cycle's pixel-level score of the floor region.
    pub fn floor_scores(&self) -> &[Option<FloorRegionScore>] {
        &self.floor_scores
    }

    /// When its next queued command is due, if one is.
    pub(crate) fn next_due_s(&self) -> Option<f64> {
        self.commands.front().map(|&(due, _, _)| due)
    }

    /// Hands the drive every queued command due by `now_s` (within half a physics step).
    pub(crate) fn deliver_due(&mut self, world: &mut World, now_s: f64, half_step_s: f64) {
        while let Some(&(due, command, ball)) = self.commands.front() {
            if due > now_s + half_step_s {
                break;
            }
            world.set_command(self.body, command);
            world.set_ball_command(self.body, ball);
            self.commands.pop_front();
        }
    }

    /// After the world moved on `dt_s`: its pan units turn, its wheels report to its software,
    /// and the truth side checks the target it headed for.
    pub(crate) fn after_step(&mut self, world: &World, dt_s: f64) {
        if let Some(c) = &mut self.cameras {
            c.advance(dt_s);
        }
        let after = world.robot_state(self.body);
        let reading = self.odometry.read(&after, dt_s);
        self.software.odometry(&reading);
        self.last_odometry = Some(reading);
        let p = Point2::from(after.pose.translation.vector);
        self.truth.targets(p, self.heading_for, world.time_s());
    }

    /// Where the axis of the camera vision uses sits on the robot.
    fn vision_mount_mm(&self) -> [f64; 2] {
        self.scenario
            .vision_sensor_index()
            .map_or([0.0, 0.0], |i| self.scenario.robot.sensors[i].mount_mm)
    }

    /// Records the cycle: the trajectory row (truth, command, estimated pose) and the robot's
    /// estimates, and scores the pose estimate.
    fn record(&mut self, world: &World, t: f64, command: VelocityCommand, estimates: Estimates) {
        let row = self.row(world, t, command, estimates.pose);
        if let Some(est) = &estimates.pose {
            let truth = Isometry2::new(Vector2::new(row.x_mm, row.y_mm), row.theta_rad);
            self.truth.checkpoint(est, &truth);
        }
        if let (Some(x), Some(y)) = (row.est_x_mm, row.est_y_mm) {
            self.truth
                .pose(Point2::new(x, y), Point2::new(row.x_mm, row.y_mm));
        }
        self.sample_progress(&row);
        self.trajectory.push(row);
        self.estimates.push(estimates);
    }

    /// With a goal: notes where the robot is in `row` and the target it is on.
    fn sample_progress(&mut self, row: &TrajectoryRow) {
        if self.has_goal() {
            self.progress.push(ProgressSample {
                t_s: row.t_s,
                x_mm: row.x_mm,
                y_mm: row.y_mm,
                target: self.truth.current_target(),
            });
        }
    }

    /// Closes its trajectory with the final state (driving runs).
    pub(crate) fn record_final_state(&mut self, world: &World) {
        let row = self.row(
            world,
            world.time_s(),
            world.command(self.body),
            self.software.estimate(),
        );
        self.sample_progress(&row);
        self.trajectory.push(row);
    }

    /// The trajectory row of the current state with `command` and the estimate.
    fn row(
        &self,
        world: &World,
        t: f64,
        command: VelocityCommand,
        est: Option<Isometry2<f64>>,
    ) -> TrajectoryRow {
        let s = world.robot_state(self.body);
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

    /// The truth now (the simulator's side, for scoring and recording only).
    pub fn truth(&self, world: &World) -> Truth {
        let s = world.robot_state(self.body);
        Truth {
            t_s: world.time_s(),
            pose: s.pose,
            velocity_mm_s: s.velocity_mm_s,
            omega_rad_s: s.omega_rad_s,
            contacts: world.stats(self.body).contacts,
            reached_goal: self.reached_goal(),
            targets_reached: self.truth.targets_reached(),
            ball: world.ball().map(|(_, b)| b),
            ball_in_dribbler: world.light_barrier(self.body),
        }
    }

    /// The name of what drove it: its software's, or the simulator's pilot.
    pub fn controller(&self) -> String {
        match self.pilot {
            Some(_) => "truth_pilot".to_string(),
            None => self.software.name(),
        }
    }

    /// The truth-side score of its run so far.
    pub(crate) fn score(&self) -> &TruthScore {
        &self.truth
    }

    /// Its figures of the run so far (a row of a team's `robots` table).
    pub fn summary(&self, world: &World) -> RobotSummary {
        let stats = world.stats(self.body);
        let navigation = self
            .estimates
            .iter()
            .rev()
            .find_map(|e| e.navigation.as_ref());
        let start = self.scenario.start().point();
        RobotSummary {
            name: self.name.clone(),
            controller: self.controller(),
            reached_goal: self.reached_goal(),
            time_to_goal_s: self.truth.time_to_goal_s(),
            goal_figures: self.goal_figures(navigation),
            contacts: stats.contacts,
            solid_contacts: stats.solid_contacts,
            robot_contacts: stats.robot_contacts,
            contacts_by_class: super::record::contact_counts(&stats.contacts_by_class),
            min_clearance_mm: stats.min_clearance_mm,
            min_robot_clearance_mm: stats.min_robot_clearance_mm,
            path_length_mm: stats.path_length_mm,
            straight_mm: self.scenario.goal.as_ref().map(|g| {
                let mut at = start;
                let mut total = 0.0;
                for t in g.targets() {
                    total += (t - at).norm();
                    at = t;
                }
                total
            }),
            peak_speed_mm_s: stats.peak_speed_mm_s,
            peak_accel_mm_s2: stats.peak_accel_mm_s2,
            freespace_error_mm: self.truth.freespace_error_mm(),
            floor_region_iou: self.truth.floor_region_iou(),
            pose_error_mm: self.truth.pose_error_mm(),
            targets_reached: self.truth.targets_reached(),
            localization_fixes: localization_fixes(&self.estimates),
            unreachable: navigation.map(|n| n.unreachable.is_some()),
            watchdog_fired: navigation.map(|n| n.watchdog),
        }
    }

    /// With a goal: how its run ended so far (reached; else unreachable when its planner last
    /// said so; else time up or stuck by its progress on the truth), and its route's
    /// reachability.
    fn goal_figures(&self, navigation: Option<&NavigationReport>) -> Option<GoalFigures> {
        let (goal, route) = (self.scenario.goal.as_ref()?, self.route?);
        let reason = navigation
            .and_then(|n| n.unreachable)
            .map(|u| u.as_str().to_string());
        let progressing = made_progress(&self.progress, &goal.targets());
        let outcome = GoalOutcome::of(self.reached_goal(), reason.is_some(), progressing);
        Some(GoalFigures {
            outcome,
            unreachable_reason: reason.filter(|_| outcome == GoalOutcome::Unreachable),
            goal_reachable: route.reachable,
            reachable_margin_mm: route.margin_mm,
        })
    }

    /// Ends its run: its trajectory, estimates and floor-region scores.
    pub(crate) fn into_records(self) -> Records {
        (self.trajectory, self.estimates, self.floor_scores)
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
    /// The ball, when there is one.
    pub ball: Option<omniloop_sim::BallState>,
    /// Whether the ball is at its dribbler, where its light barrier sees it.
    pub ball_in_dribbler: bool,
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
    let index = scenario
        .vision_sensor_index()
        .map_err(|e| SimError::Invalid(e.to_string()))?;
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
    let index = scenario
        .vision_sensor_index()
        .map_err(|e| SimError::Invalid(e.to_string()))?;
    Ok(vec![calibrate_columns(
        &scenario.robot.sensors[index],
        scenario.seed,
    )?])
}

/// The fixes the estimator used (set or pulled its estimate by), when the robot localizes on
/// the floor region (its `floor_localization` stage reported a fix or why it found none).
pub fn localization_fixes(records: &[Estimates]) -> Option<usize> {
    const STAGE: &str = floor_localization::NAME;
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
