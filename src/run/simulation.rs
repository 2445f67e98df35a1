//! The closed loop on the simulator's side: render the robots' cameras, hand each robot's
//! software what its own sensors give, apply their commands, step the world once, and record
//! the truth beside what each robot believes. One robot ([`Agent`]) for a one-robot scenario,
//! one for each robot of a team: their cameras are traced together (on the CPU in parallel
//! across robots and pixels, on a GPU in one batch a cycle), their software runs in parallel,
//! and the same scenario and seed give the same run whatever the number of threads.

use super::agent::{Agent, CameraSetup, SoftwareBuilder, Truth};
use super::ball_record::{self, BallOutput, BallRow, BallSummary};
use super::cameras::sensor_noise_seed;
use super::error::RunError;
use super::observer::{CycleView, ObserverHandle, RobotCycle};
use super::outcome::{GoalFigures, GoalOutcome};
use super::pilot::Pilot;
use super::record::{ContactCounts, RobotSummary, Summary, TeamFigures, TrajectoryRow};
use super::score::FloorRegionScore;
use crate::scenario::Scenario;
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_control::AccelLimitedDrive;
use omniloop_robot::{
    ActuatorState, Estimates, Frame, OdometryReading, Outputs, Robot, RobotConfig, RobotError,
    RobotSoftware,
};
use omniloop_sim::render::{BatchHandle, BatchServer, TruthFrame};
use omniloop_sim::{Renderer, RendererChoice, Scene, SensorNoise, SimError, World};
use omniloop_vision::RadialCalibration;
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Duration;

/// How to run a scenario (what the command line adds to the scenario file).
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Which renderer traces the cameras' images.
    pub renderer: RendererChoice,
    /// Save every camera's image every this many cycles (with `frames_dir`).
    pub save_frames_every: Option<u64>,
    /// Where saved frames go.
    pub frames_dir: Option<PathBuf>,
    /// Trace each frame's truth beside it (depth, labels; saved with the frames, recorded, and
    /// the free space scored pixel by pixel). The robot's software never gets it.
    pub truth: bool,
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
    /// With the truth traced: each cycle's floor-region score, pixel by pixel (empty
    /// otherwise).
    pub floor_scores: Vec<Option<FloorRegionScore>>,
    /// The paths of the other robots, one point a control cycle.
    pub other_paths: Vec<Vec<Point2<f64>>>,
    /// Files of the experiment's own (tables, figures), written beside the run's.
    pub files: Vec<OutputFile>,
    /// The map the robot's software built, when it builds one.
    pub map: Option<omniloop_robot::MapSnapshot>,
    /// A team's robots, each with its records (empty for a one-robot scenario, whose records
    /// are the fields above).
    pub robots: Vec<RobotOutput>,
    /// With a ball: its state every cycle and the game's events.
    pub ball: Option<BallOutput>,
}

/// What one robot of a team left behind.
#[derive(Debug, Clone)]
pub struct RobotOutput {
    /// Its name.
    pub name: String,
    /// One row a control cycle, and the final state.
    pub trajectory: Vec<TrajectoryRow>,
    /// What it believed, one record a control cycle.
    pub estimates: Vec<Estimates>,
    /// With the truth traced: each cycle's floor-region score (empty otherwise).
    pub floor_scores: Vec<Option<FloorRegionScore>>,
    /// The map its software built, when it builds one.
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

/// A scenario being run, one control cycle at a time.
pub struct Simulation {
    scenario: Scenario,
    world: World,
    agents: Vec<Agent>,
    others: Vec<Pilot>,
    cycle: u64,
    other_paths: Vec<Vec<Point2<f64>>>,
    /// With a ball: its state at the start of every cycle.
    ball_rows: Vec<BallRow>,
    /// Every robot body's name, in the world's order (scripted robots as `other_robots[k]`).
    body_names: Vec<String>,
    options: RunOptions,
    /// A team's GPU, which traces every robot's frames of a cycle in one batch (dropped
    /// after the agents, which hold its clients).
    _gpu: Option<BatchServer>,
}

/// How long a team's GPU waits for the frames of a cycle before it traces those it has.
const TEAM_BATCH_WAIT: Duration = Duration::from_millis(20);

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

    /// Builds the world and the cameras of a validated scenario, with each robot's software
    /// that `software` builds from what the robot is told ([`RobotConfig`]: its name, start,
    /// body, cameras and their calibrations, goal, map; never the world).
    pub fn with_software(
        scenario: &Scenario,
        options: &RunOptions,
        mut software: impl FnMut(&RobotConfig) -> Result<Box<dyn RobotSoftware>, RobotError>,
        notice: impl FnOnce(&str),
    ) -> Result<Self, RunError> {
        let world = World::new(
            &scenario.world,
            &scenario.robot_bodies(),
            scenario.run.physics_step_s,
        )?;
        let mut notice = Some(notice);
        let mut say = |m: &str| {
            if let Some(n) = notice.take() {
                n(m);
            }
        };
        let members = scenario.members();
        let names = scenario.robot_names();
        if let Some(dir) = &options.frames_dir {
            frame_folders(dir, scenario.is_team().then_some(names.as_slice()))?;
        }
        let (renderer, gpu) = team_renderer(members.len(), options, &mut say)?;
        let shared = options
            .shared_gpu
            .clone()
            .or(gpu.as_ref().map(BatchServer::handle));
        let mut agents = Vec::with_capacity(members.len());
        for (k, (member, name)) in members.iter().zip(&names).enumerate() {
            let setup = CameraSetup {
                renderer,
                shared_gpu: shared.as_ref(),
                all: options.save_frames_every.is_some(),
                truth: options.truth,
            };
            let build: &mut SoftwareBuilder<'_> = &mut software;
            let agent = Agent::new(
                name,
                k,
                member,
                options.takes_frames,
                setup,
                build,
                &mut say,
            )
            .map_err(|e| in_robot(members.len(), name, e))?;
            agents.push(agent);
        }
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
        for o in &options.observers {
            o.with(|o| o.start(&world, &names));
        }
        let body_names = (0..scenario.robot_bodies().len())
            .map(|i| ball_record::robot_name(&names, i))
            .collect();
        Ok(Self {
            scenario: scenario.clone(),
            world,
            ball_rows: Vec::new(),
            body_names,
            other_paths: vec![Vec::new(); others.len()],
            others,
            agents,
            cycle: 0,
            options: options.clone(),
            _gpu: gpu,
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

    /// The robots with software: the one robot, or a team's in the scenario's order.
    pub fn robots(&self) -> &[Agent] {
        &self.agents
    }

    /// The robots with software, to reach their software between cycles.
    pub fn robots_mut(&mut self) -> &mut [Agent] {
        &mut self.agents
    }

    /// The robot called `name`, if there is one.
    pub fn robot_named(&self, name: &str) -> Option<&Agent> {
        self.agents.iter().find(|a| a.name() == name)
    }

    /// The truth of robot `k` now (the simulator's side, for scoring and recording only).
    pub fn truth_of(&self, k: usize) -> Option<Truth> {
        self.agents.get(k).map(|a| a.truth(&self.world))
    }

    /// The first robot: the one robot of a one-robot scenario.
    fn first(&self) -> &Agent {
        &self.agents[0]
    }

    /// The robot's software (the first robot's in a team).
    pub fn robot_mut(&mut self) -> &mut dyn RobotSoftware {
        self.agents[0].software_mut()
    }

    /// Control cycles run so far.
    pub fn cycle(&self) -> u64 {
        self.cycle
    }

    /// The trajectory recorded so far, a row a cycle (and the final state once recorded).
    pub fn trajectory(&self) -> &[TrajectoryRow] {
        self.first().trajectory()
    }

    /// What the robot believed, a record a cycle so far.
    pub fn estimates(&self) -> &[Estimates] {
        self.first().estimates()
    }

    /// What the robot believed in the last cycle.
    pub fn last_estimates(&self) -> Option<&Estimates> {
        self.estimates().last()
    }

    /// The true pose of the robot under test when the last cycle's frames were taken.
    pub fn last_truth_pose(&self) -> Option<Isometry2<f64>> {
        self.trajectory()
            .last()
            .map(|r| Isometry2::new(Vector2::new(r.x_mm, r.y_mm), r.theta_rad))
    }

    /// Whether the run is over: time is up, or every robot with a goal reached it and the run
    /// stops there.
    pub fn finished(&self) -> bool {
        let with_goal = || self.agents.iter().filter(|a| a.has_goal());
        self.cycle >= self.scenario.max_cycles()
            || (self.scenario.run.stop_at_goal
                && with_goal().count() > 0
                && with_goal().all(Agent::reached_goal))
    }

    /// The calibration of the camera the robot's vision uses, when its software uses one.
    pub fn vision_calibration(&self) -> Option<&RadialCalibration> {
        self.first().vision_calibration()
    }

    /// Renders the camera the robot's vision uses as it sees the world now, with its noise (a
    /// frame of its own, as an experimenter would take one): `None` when no camera is rendered.
    pub fn vision_frame(&mut self) -> Result<Option<&image::RgbaImage>, RunError> {
        let agent = &mut self.agents[0];
        let scenario = agent.scenario();
        let index = scenario.vision_sensor_index().ok();
        let name = index.map(|i| scenario.robot.sensors[i].name.clone());
        let body = agent.body();
        match (agent.cameras_mut(), name) {
            (Some(c), Some(name)) => {
                c.capture(&self.world, body)?;
                Ok(c.image(&name))
            }
            _ => Ok(None),
        }
    }

    /// Puts the ball at `position_mm` on the floor going at `velocity_mm_s` (an experimenter
    /// placing it; a dribbler holding it lets go): an error without a ball, or off the floor.
    pub fn place_ball(
        &mut self,
        position_mm: Point2<f64>,
        velocity_mm_s: Vector2<f64>,
    ) -> Result<(), RunError> {
        let finite = position_mm
            .iter()
            .chain(velocity_mm_s.iter())
            .all(|v| v.is_finite());
        let why = match self.world.ball() {
            None => Some("the scenario has no ball ([world.ball])".to_string()),
            Some(_) if !finite => Some("place and velocity must be finite".to_string()),
            Some(_) if !self.world.layout().is_floor(position_mm) => Some(format!(
                "({}, {}) mm is outside the floor region",
                position_mm.x, position_mm.y
            )),
            Some(_) => None,
        };
        if let Some(why) = why {
            return Err(RunError::Actuator(format!("placing the ball: {why}")));
        }
        self.world.place_ball(position_mm, velocity_mm_s);
        Ok(())
    }

    /// Puts the robot under test at `pose`, at rest (an experimenter carrying it there).
    pub fn place_robot(&mut self, pose: Isometry2<f64>) {
        self.world.place_robot(0, pose);
    }

    /// The ball placed last rolls from the start instead of sliding first (see
    /// [`World::set_ball_rolling`]).
    pub fn set_ball_rolling(&mut self) {
        self.world.set_ball_rolling();
    }

    /// Puts robot `k` of the team (in [`Simulation::robots`]' order) at `pose`, at rest, and
    /// tells its software that it was carried (its pose is unknown until it finds it again).
    pub fn carry_robot(&mut self, k: usize, pose: Isometry2<f64>) {
        if let Some(a) = self.agents.get_mut(k) {
            self.world.place_robot(a.body(), pose);
            a.software_mut().forget_pose();
        }
    }

    /// One control cycle: the cameras see ([`Simulation::sense`]), then the robots' software
    /// decides and the world moves on ([`Simulation::act`]).
    pub fn step(&mut self) -> Result<(), RunError> {
        self.sense()?;
        self.act()
    }

    /// The first half of a control cycle: renders the cameras each robot's software reads now
    /// (every camera when frames are saved) as the world is at the cycle's start, and saves
    /// them when asked. [`Simulation::frames`] gives them until the next sense.
    pub fn sense(&mut self) -> Result<(), RunError> {
        let scene = Scene::of_world(&self.world);
        let now = self.world.time_s();
        let all = self.options.save_frames_every.is_some();
        let save_dir = match (self.options.save_frames_every, &self.options.frames_dir) {
            (Some(every), Some(dir)) if every > 0 && self.cycle.is_multiple_of(every) => Some(dir),
            _ => None,
        };
        let team = self.agents.len() > 1;
        let cycle = self.cycle;
        let states: Vec<_> = self
            .agents
            .iter()
            .map(|a| self.world.robot_state(a.body()))
            .collect();
        let sense = |a: &mut Agent, state| -> Result<(), RunError> {
            let dir = save_dir.map(|d| if team { d.join(a.name()) } else { d.clone() });
            let save = dir.as_deref().map(|d| (d, cycle));
            let name = a.name().to_string();
            a.sense(&scene, state, now, all, save)
                .map_err(|e| in_robot(usize::from(team) + 1, &name, e))
        };
        if !team {
            return sense(&mut self.agents[0], states[0]);
        }
        if self._gpu.is_some() || self.options.shared_gpu.is_some() {
            // The robots' frames wait together for the GPU's batch: a thread each.
            return std::thread::scope(|scope| {
                let handles: Vec<_> = self
                    .agents
                    .iter_mut()
                    .zip(states)
                    .map(|(a, state)| scope.spawn(move || sense(a, state)))
                    .collect();
                handles
                    .into_iter()
                    .try_for_each(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            });
        }
        self.agents
            .par_iter_mut()
            .zip(states)
            .try_for_each(|(a, state)| sense(a, state))
    }

    /// The frames the robot's software gets after the last [`Simulation::sense`], stamped
    /// with the time they were taken (none without cameras).
    pub fn frames(&self) -> Vec<Frame<'_>> {
        self.first().frames()
    }

    /// The wheel odometry's reading at the end of the last cycle, as the robot's software got
    /// it (none before the first cycle).
    pub fn last_odometry(&self) -> Option<OdometryReading> {
        self.first().last_odometry()
    }

    /// The state of the robot's actuators (its pan units, its kicker) now.
    pub fn actuator_state(&self) -> Vec<ActuatorState> {
        self.first().actuator_state(&self.world)
    }

    /// The second half of a control cycle: each robot's software decides on the frames of
    /// the last [`Simulation::sense`] (in parallel in a team), their commands are applied and
    /// recorded, the world advances one period, the wheels report.
    pub fn act(&mut self) -> Result<(), RunError> {
        let t = self.world.time_s();
        let team = self.agents.len();
        let kickers: Vec<_> = (self.agents.iter())
            .map(|a| a.kicker_state(&self.world))
            .collect();
        let outputs: Vec<Result<Outputs, RunError>> = if team == 1 {
            vec![self.agents[0].decide(t, kickers[0].clone())]
        } else {
            (self.agents.par_iter_mut().zip(kickers))
                .map(|(a, k)| a.decide(t, k))
                .collect()
        };
        for (a, out) in self.agents.iter_mut().zip(outputs) {
            let name = a.name().to_string();
            out.and_then(|out| a.apply(&self.world, t, out))
                .map_err(|e| in_robot(team, &name, e))?;
        }
        self.drive_others();
        self.ball_rows
            .extend(BallRow::of(&self.world, &self.body_names));
        self.observe();

        let dt = self.scenario.run.control_period_s;
        self.advance_applying_commands(t + dt);
        self.cycle += 1;
        for a in &mut self.agents {
            a.after_step(&self.world, dt);
        }
        Ok(())
    }

    /// Moves the world on to `end_s`, each robot's queued commands reaching its drive when
    /// they are due (`[robot.timing] command_latency_s` after the software gave them; at once
    /// without one).
    fn advance_applying_commands(&mut self, end_s: f64) {
        let half_step = 0.5 * self.scenario.run.physics_step_s;
        loop {
            let now = self.world.time_s();
            for a in &mut self.agents {
                a.deliver_due(&mut self.world, now, half_step);
            }
            let next = self
                .agents
                .iter()
                .filter_map(Agent::next_due_s)
                .min_by(f64::total_cmp);
            match next {
                Some(due) if due < end_s - half_step => self.world.advance(due - now),
                _ => {
                    self.world.advance(end_s - now);
                    return;
                }
            }
        }
    }

    /// The other robots drive on, each by its pilot on its true position.
    fn drive_others(&mut self) {
        let first = self.agents.len();
        for (k, pilot) in self.others.iter_mut().enumerate() {
            let p = Point2::from(self.world.robot_state(first + k).pose.translation.vector);
            self.other_paths[k].push(p);
            let cmd = pilot.command(p);
            self.world.set_command(first + k, cmd);
        }
    }

    /// Shows the cycle just recorded to the observers.
    fn observe(&self) {
        if self.options.observers.is_empty() {
            return;
        }
        let mut robots = Vec::with_capacity(self.agents.len());
        for a in &self.agents {
            let (Some(row), Some(estimates)) = (a.trajectory().last(), a.estimates().last()) else {
                return;
            };
            robots.push(RobotCycle {
                name: a.name(),
                row,
                estimates,
                frames: a.frames(),
                truth: a.truth_frames(),
                floor: a.floor_scores().last().and_then(Option::as_ref),
            });
        }
        let solids = self.world.robot_solids(None);
        let view = CycleView {
            cycle: self.cycle,
            robots: &robots,
            ball: self
                .ball_rows
                .last()
                .zip(self.world.ball().map(|(spec, _)| spec)),
            others: &solids[self.agents.len().min(solids.len())..],
        };
        for o in &self.options.observers {
            o.with(|o| o.cycle(&view));
        }
    }

    /// Closes every robot's trajectory with the final state (driving runs).
    pub fn record_final_state(&mut self) {
        for a in &mut self.agents {
            a.record_final_state(&self.world);
        }
        self.ball_rows
            .extend(BallRow::of(&self.world, &self.body_names));
    }

    /// With a ball: its records so far.
    fn ball_output(&self) -> Option<BallOutput> {
        self.world.ball()?;
        let names = &self.body_names;
        Some(BallOutput {
            rows: self.ball_rows.clone(),
            events: (self.world.ball_events().iter())
                .map(|e| ball_record::named_event(e, names))
                .collect(),
        })
    }

    /// The truth now: the robot's true pose and velocity, its contacts so far and whether
    /// it has reached the goal (the first robot's in a team; [`Simulation::truth_of`] gives
    /// any robot's).
    pub fn truth(&self) -> Truth {
        self.first().truth(&self.world)
    }

    /// Ends the run: the summary of what the truth shows, and everything recorded.
    pub fn finish(mut self, wall_time_s: f64) -> RunOutput {
        let ends = self.other_robot_ends();
        for (path, end) in self.other_paths.iter_mut().zip(ends) {
            path.push(end);
        }
        let summary = self.summary(wall_time_s);
        let team = self.scenario.is_team();
        let ball = self.ball_output();
        let mut out = RunOutput {
            ball,
            summary,
            map: None,
            trajectory: Vec::new(),
            estimates: Vec::new(),
            floor_scores: Vec::new(),
            other_paths: self.other_paths,
            files: Vec::new(),
            robots: Vec::new(),
        };
        for a in self.agents {
            let map = a.software().map();
            let name = a.name().to_string();
            let (trajectory, estimates, floor_scores) = a.into_records();
            if team {
                out.robots.push(RobotOutput {
                    name,
                    trajectory,
                    estimates,
                    floor_scores,
                    map,
                });
            } else {
                (out.trajectory, out.estimates, out.map) = (trajectory, estimates, map);
                out.floor_scores = floor_scores;
            }
        }
        out
    }

    /// What [`Simulation::finish`] would give now, the run going on (its records copied).
    pub fn output(&self, wall_time_s: f64) -> RunOutput {
        let mut other_paths = self.other_paths.clone();
        for (path, end) in other_paths.iter_mut().zip(self.other_robot_ends()) {
            path.push(end);
        }
        let team = self.scenario.is_team();
        let first = self.first();
        RunOutput {
            ball: self.ball_output(),
            summary: self.summary(wall_time_s),
            map: if team { None } else { first.software().map() },
            trajectory: if team {
                Vec::new()
            } else {
                first.trajectory().to_vec()
            },
            estimates: if team {
                Vec::new()
            } else {
                first.estimates().to_vec()
            },
            floor_scores: if team {
                Vec::new()
            } else {
                first.floor_scores().to_vec()
            },
            other_paths,
            files: Vec::new(),
            robots: if team {
                self.agents
                    .iter()
                    .map(|a| RobotOutput {
                        name: a.name().to_string(),
                        trajectory: a.trajectory().to_vec(),
                        estimates: a.estimates().to_vec(),
                        floor_scores: a.floor_scores().to_vec(),
                        map: a.software().map(),
                    })
                    .collect()
            } else {
                Vec::new()
            },
        }
    }

    /// Where the other robots are now.
    fn other_robot_ends(&self) -> Vec<Point2<f64>> {
        let first = self.agents.len();
        (0..self.others.len())
            .map(|k| Point2::from(self.world.robot_state(first + k).pose.translation.vector))
            .collect()
    }

    /// The summary of what the truth shows so far: the robot's, or for a team the team's
    /// (its keys over all robots, its own figures, and a row a robot).
    fn summary(&self, wall_time_s: f64) -> Summary {
        let first = self.first();
        let r = first.summary(&self.world);
        let summary = Summary {
            scenario: self.scenario.name.clone(),
            seed: self.scenario.seed,
            controller: r.controller,
            cycles: self.cycle,
            sim_time_s: self.world.time_s(),
            wall_time_s,
            cycles_per_s: 0.0,
            wall_contacts: r.contacts,
            contacts_by_class: r.contacts_by_class,
            peak_speed_mm_s: r.peak_speed_mm_s,
            peak_accel_mm_s2: r.peak_accel_mm_s2,
            reached_goal: r.reached_goal,
            time_to_goal_s: r.time_to_goal_s,
            goal_figures: r.goal_figures,
            min_clearance_mm: r.min_clearance_mm,
            path_length_mm: r.path_length_mm,
            renderer: first.renderer_name().map(str::to_string),
            freespace_error_mm: r.freespace_error_mm,
            floor_region_iou: r.floor_region_iou,
            pose_error_mm: r.pose_error_mm,
            targets_reached: r.targets_reached,
            localization_fixes: r.localization_fixes,
            checkpoint_heading_error_deg: first.score().checkpoint_heading_errors_deg(),
            unreachable: r.unreachable,
            watchdog_fired: r.watchdog_fired,
            team: None,
            robots: None,
            ball: BallSummary::of(&self.world, &self.body_names),
            experiment: serde_json::Map::new(),
        };
        if self.scenario.is_team() {
            self.team_summary(summary)
        } else {
            summary
        }
    }

    /// A team's summary: `base`'s keys over every robot (contacts of all, every goal reached
    /// and when the last was, the least clearance, the total path, the largest speed and
    /// acceleration), the team's figures and a row a robot.
    fn team_summary(&self, base: Summary) -> Summary {
        let rows: Vec<_> = self.agents.iter().map(|a| a.summary(&self.world)).collect();
        let figures = team_figures(&self.world, &self.agents, &rows);
        let controllers: Vec<&str> = rows.iter().map(|r| r.controller.as_str()).collect();
        let mut names: Vec<&str> = controllers.clone();
        names.dedup();
        Summary {
            controller: names.join("+"),
            wall_contacts: figures.solid_contacts + figures.robot_contacts,
            contacts_by_class: team_contacts(&rows, figures.robot_contacts),
            peak_speed_mm_s: rows.iter().map(|r| r.peak_speed_mm_s).fold(0.0, f64::max),
            peak_accel_mm_s2: rows.iter().map(|r| r.peak_accel_mm_s2).fold(0.0, f64::max),
            reached_goal: figures.with_goal > 0 && figures.all_arrived,
            time_to_goal_s: figures.last_arrival_s,
            goal_figures: team_goal_figures(&rows),
            min_clearance_mm: rows
                .iter()
                .map(|r| r.min_clearance_mm)
                .fold(f64::INFINITY, f64::min),
            path_length_mm: rows.iter().map(|r| r.path_length_mm).sum(),
            freespace_error_mm: None,
            floor_region_iou: None,
            pose_error_mm: None,
            targets_reached: None,
            localization_fixes: None,
            checkpoint_heading_error_deg: None,
            unreachable: rows
                .iter()
                .any(|r| r.unreachable.is_some())
                .then(|| rows.iter().any(|r| r.unreachable == Some(true))),
            watchdog_fired: None,
            team: Some(figures),
            robots: Some(rows),
            ..base
        }
    }
}

/// A team's goal figures over its robots with a goal: the worst outcome
/// ([`GoalOutcome::worst`]), with the reasons of the robots that reported unreachable when
/// that is the team's; every route reachable, and the narrowest margin. `None` when no robot
/// has a goal.
fn team_goal_figures(rows: &[RobotSummary]) -> Option<GoalFigures> {
    let figures: Vec<&GoalFigures> = rows
        .iter()
        .filter_map(|r| r.goal_figures.as_ref())
        .collect();
    let outcome = GoalOutcome::worst(figures.iter().map(|f| f.outcome))?;
    let mut reasons: Vec<&str> = figures
        .iter()
        .filter_map(|f| f.unreachable_reason.as_deref())
        .collect();
    reasons.sort_unstable();
    reasons.dedup();
    let reachable = figures.iter().all(|f| f.goal_reachable);
    Some(GoalFigures {
        outcome,
        unreachable_reason: (outcome == GoalOutcome::Unreachable && !reasons.is_empty())
            .then(|| reasons.join("+")),
        goal_reachable: reachable,
        reachable_margin_mm: figures
            .iter()
            .map(|f| f.reachable_margin_mm)
            .collect::<Option<Vec<f64>>>()
            .and_then(|m| m.into_iter().reduce(f64::min)),
    })
}

/// The team's touches by class: its robots' own, a touch between two robots once
/// (`robot_touches`), so that they add up to the team's `wall_contacts`.
fn team_contacts(rows: &[RobotSummary], robot_touches: u32) -> ContactCounts {
    let mut all = ContactCounts::new();
    for (class, n) in rows.iter().flat_map(|r| &r.contacts_by_class) {
        *all.entry(class.clone()).or_default() += n;
    }
    let robot = omniloop_sim::labels::Class::Robot.name().to_string();
    all.remove(&robot);
    if robot_touches > 0 {
        all.insert(robot, robot_touches);
    }
    all
}

/// A team's figures from its robots' rows and the world's record of touches.
fn team_figures(world: &World, agents: &[Agent], rows: &[RobotSummary]) -> TeamFigures {
    let with_goal: Vec<(&Agent, &RobotSummary)> = agents
        .iter()
        .zip(rows)
        .filter(|(a, _)| a.has_goal())
        .collect();
    let arrived = with_goal.iter().filter(|(_, r)| r.reached_goal).count();
    let all_arrived = arrived == with_goal.len();
    let last_arrival_s = all_arrived
        .then(|| {
            with_goal
                .iter()
                .filter_map(|(_, r)| r.time_to_goal_s)
                .fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.max(t))))
        })
        .flatten();
    let straight_line_time_s = with_goal
        .iter()
        .filter_map(|(a, _)| straight_line_time_s(a.scenario()))
        .fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.max(t))));
    // As the clutter benchmark's path_ratio: the way to the goal ends at its tolerance.
    let path: f64 = with_goal.iter().map(|(_, r)| r.path_length_mm).sum();
    let straight: f64 = with_goal
        .iter()
        .filter_map(|(a, r)| {
            let tolerance = a.scenario().goal.as_ref().map_or(0.0, |g| g.tolerance_mm);
            r.straight_mm.map(|s| (s - tolerance).max(0.0))
        })
        .sum();
    let team: Vec<usize> = agents.iter().map(Agent::body).collect();
    TeamFigures {
        robots: agents.len(),
        with_goal: with_goal.len(),
        arrived,
        all_arrived,
        last_arrival_s,
        straight_line_time_s,
        time_ratio: last_arrival_s
            .zip(straight_line_time_s)
            .filter(|(_, s)| *s > 0.0)
            .map(|(t, s)| t / s),
        solid_contacts: rows.iter().map(|r| r.solid_contacts).sum(),
        robot_contacts: world
            .robot_touches()
            .iter()
            .filter(|t| team.contains(&t.0) || team.contains(&t.1))
            .count() as u32,
        min_robot_clearance_mm: rows
            .iter()
            .map(|r| r.min_robot_clearance_mm)
            .fold(f64::INFINITY, f64::min),
        path_ratio: (straight > 0.0).then(|| path / straight),
    }
}

/// The time a robot needs along the straight lines from its start through its targets at its
/// top speed, accelerating and braking at its limit and stopping at each target: per leg of
/// length `d`, `d / v + v / a` when it reaches `v`, else `2 sqrt(d / a)`.
pub fn straight_line_time_s(s: &Scenario) -> Option<f64> {
    let goal = s.goal.as_ref()?;
    let (v, a) = (s.robot.max_speed_mm_s, s.robot.accel_limit_mm_s2);
    let mut at = s.start().point();
    let mut total = 0.0;
    for t in goal.targets() {
        let d = (t - at).norm();
        total += if d > v * v / a {
            d / v + v / a
        } else {
            2.0 * (d / a).sqrt()
        };
        at = t;
    }
    Some(total)
}

/// The renderer every robot of a run opens: the choice for one robot; for a team, the CPU
/// renderer each, or one GPU that traces the team's frames in one batch a cycle (returned,
/// to be shared).
fn team_renderer(
    robots: usize,
    options: &RunOptions,
    notice: &mut dyn FnMut(&str),
) -> Result<(RendererChoice, Option<BatchServer>), RunError> {
    if robots == 1 || options.shared_gpu.is_some() || options.renderer == RendererChoice::Cpu {
        return Ok((options.renderer, None));
    }
    let renderer = Renderer::new(options.renderer, |m| notice(m))?;
    Ok(match renderer.into_gpu() {
        Some(gpu) => (
            RendererChoice::Gpu,
            Some(BatchServer::start(gpu, TEAM_BATCH_WAIT)),
        ),
        None => (RendererChoice::Cpu, None),
    })
}

/// Makes the folder saved frames go to: `dir`, or with a team's `robots` a folder in it for
/// each robot.
fn frame_folders(dir: &std::path::Path, robots: Option<&[String]>) -> Result<(), RunError> {
    let folders: Vec<PathBuf> = match robots {
        Some(names) => names.iter().map(|n| dir.join(n)).collect(),
        None => vec![dir.to_path_buf()],
    };
    for path in folders {
        std::fs::create_dir_all(&path).map_err(|e| RunError::Frame {
            path,
            reason: image::ImageError::IoError(e),
        })?;
    }
    Ok(())
}

/// A robot's error, named by the robot when it is one of a team.
fn in_robot(robots: usize, name: &str, e: RunError) -> RunError {
    if robots > 1 {
        RunError::InRobot {
            robot: name.to_string(),
            message: e.to_string(),
        }
    } else {
        e
    }
}

/// The built-in robot software of a configuration.
pub fn builtin_software(config: &RobotConfig) -> Result<Box<dyn RobotSoftware>, RobotError> {
    Ok(Box::new(Robot::new(config)?))
}

/// Renders what sensor `sensor` of the robot under test (a team's first robot) sees when the
/// robot stands at `pose` (the scenario's start when `None`) and every other robot at its
/// start, with the sensor's noise drawn as the first frame of a run would be, or clean when
/// `noise` is false.
pub fn render_snapshot(
    scenario: &Scenario,
    renderer: &mut Renderer,
    sensor: Option<&str>,
    pose: Option<Isometry2<f64>>,
    noise: bool,
) -> Result<image::RgbaImage, RunError> {
    let shot = Snapshot::of(scenario, sensor, pose)?;
    let mut noise_source = noise.then(|| SensorNoise::new(shot.noise_seed));
    Ok(renderer.render(&shot.scene, &shot.sensor, &shot.pose, noise_source.as_mut())?)
}

/// [`render_snapshot`] with the frame's truth beside it (depth, floor distance, labels).
pub fn render_snapshot_truth(
    scenario: &Scenario,
    renderer: &mut Renderer,
    sensor: Option<&str>,
    pose: Option<Isometry2<f64>>,
    noise: bool,
) -> Result<(image::RgbaImage, TruthFrame), RunError> {
    let shot = Snapshot::of(scenario, sensor, pose)?;
    let mut noise_source = noise.then(|| SensorNoise::new(shot.noise_seed));
    let poses = [shot.pose];
    Ok(renderer.render_exposed_truth(&shot.scene, &shot.sensor, &poses, noise_source.as_mut())?)
}

/// What a snapshot shows: the scene, the sensor, the robot's pose and the sensor's noise seed.
struct Snapshot {
    scene: Scene,
    sensor: omniloop_sim::Sensor,
    pose: Isometry2<f64>,
    noise_seed: u64,
}

impl Snapshot {
    fn of(
        scenario: &Scenario,
        sensor: Option<&str>,
        pose: Option<Isometry2<f64>>,
    ) -> Result<Self, RunError> {
        let own = scenario.member(0);
        let index = own
            .sensor_index(sensor)
            .map_err(|e| SimError::Invalid(format!("scenario {:?}: {e}", scenario.name)))?;
        let mut bodies = scenario.robot_bodies();
        if let Some(p) = pose {
            bodies[0].start = p;
        }
        let world = World::new(&scenario.world, &bodies, scenario.run.physics_step_s)?;
        Ok(Self {
            scene: Scene::of_world(&world),
            sensor: own.robot.sensors[index].build(),
            pose: world.robot_state(0).pose,
            noise_seed: sensor_noise_seed(own.seed, index),
        })
    }
}
