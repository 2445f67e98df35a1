//! [`SslSimulator`]: a scenario run as a Small-Size simulator, without the network. It takes
//! the protocol's datagrams as bytes and answers with bytes; each [`SslSimulator::step`] runs
//! one control cycle (every robot's cameras rendered on its own truth, as in any run) and
//! gives what ssl-vision and the referee send. The server (module `server`) moves the bytes;
//! tests and the lockstep mode drive it directly. Its protocol side is an [`SslLink`] that
//! takes the simulation as an argument, so that a host owning a simulation of its own can
//! serve the protocol beside it: [`SslSoftware`] builds the protocol robots' software, then
//! [`SslLink::before_cycle`] and [`SslLink::after_cycle`] go round each cycle.
//!
//! The protocol's robots run [`Remote`] software: the team's AI is their software, and like
//! any robot software it gets no world, only what the league gives it (vision, referee,
//! feedback). The simulator's side turns a field-frame command into the robot's frame with
//! its true heading, as a robot's firmware does with its gyro.

use super::commands::{Abilities, Drive, Judged, error, judge};
use super::referee_out::RefereeOut;
use super::vision_out::{Capture, OverheadVision, SeenRobot};
use super::wire::referee::{Command, Referee};
use super::wire::sim::{
    RobotControl, RobotControlResponse, RobotFeedback, SimulatorError, SimulatorResponse,
};
use super::wire::vision::{DetectionFrame, WrapperPacket};
use super::wire::{WireError, decode};
use crate::run::{RunError, RunOptions, RunOutput, Simulation, builtin_software};
use crate::scenario::Scenario;
use crate::scenario::ssl::{SslSpec, TeamColor};
use nalgebra::{Isometry2, Point3, Rotation2, Vector2};
use omniloop_robot::boundary::{ActuatorCommand, BodyCommand};
use omniloop_robot::remote::{Remote, RemoteHandle};
use omniloop_robot::{RobotConfig, RobotSoftware};
use prost::Message;
use std::collections::HashMap;

/// Why a scenario cannot be served.
#[derive(Debug, thiserror::Error)]
pub enum SslError {
    /// The scenario's `[ssl]` table or its field do not make a Small-Size game.
    #[error("[ssl]: {0}")]
    Spec(String),
    /// The run failed.
    #[error(transparent)]
    Run(#[from] RunError),
}

/// One robot of either team.
pub(crate) struct SslRobot {
    pub(crate) team: TeamColor,
    pub(crate) id: u32,
    /// Its index in the simulation's robots.
    pub(crate) agent: usize,
    /// Its body in the world.
    pub(crate) body: usize,
    /// The handle its protocol commands go through (none: it runs its scenario software).
    pub(crate) remote: Option<RemoteHandle>,
    pub(crate) drive: Drive,
    /// When it last heard a command, s (none: never, or timed out since).
    pub(crate) heard_s: Option<f64>,
    pub(crate) present: bool,
    pub(crate) abilities: Abilities,
    pub(crate) radius_mm: f64,
    pub(crate) height_mm: f64,
}

/// What a cycle sends: vision's wrapper packets and the referee's packet, encoded.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Outgoing {
    /// Simulated time at the end of the cycle, s.
    pub t_s: f64,
    /// `SSL_WrapperPacket`s: a detection frame each, or geometry.
    pub vision: Vec<Vec<u8>>,
    /// The detection frames of the cycle (for a lockstep answer).
    pub detections: Vec<DetectionFrame>,
    /// A `Referee` packet, when one is due.
    pub referee: Option<Vec<u8>>,
}

/// Tallies of what came in, for the user and the tests.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Tallies {
    /// Datagrams taken.
    pub datagrams: u64,
    /// Datagrams that did not decode.
    pub malformed: u64,
    /// Errors answered.
    pub errors: u64,
}

/// The protocol's side of a game, beside the simulation it serves (which it takes as an
/// argument): the teams' robots and their held commands, the overhead vision, the referee.
/// [`SslSimulator`] pairs it with its simulation; a host that owns the simulation otherwise
/// (the Python package's) holds one beside it.
pub struct SslLink {
    pub(crate) spec: SslSpec,
    pub(crate) robots: Vec<SslRobot>,
    pub(crate) by_id: HashMap<(TeamColor, u32), usize>,
    vision: OverheadVision,
    referee: RefereeOut,
    last_geometry_s: Option<f64>,
    /// Simulated time over wall time the protocol asked for.
    pub(crate) speed: f64,
    /// A vision port the protocol asked for.
    pub(crate) vision_port: Option<u16>,
    pub(crate) tallies: Tallies,
}

/// The software of a scenario's robots under the protocol: [`Remote`] for the protocol's
/// teams, the handles kept for the [`SslLink`].
pub struct SslSoftware {
    spec: SslSpec,
    teams: HashMap<String, (TeamColor, u32)>,
    handles: HashMap<String, RemoteHandle>,
}

impl SslSoftware {
    /// The plan for a validated scenario: its `[ssl]` table (defaults without one) checked.
    pub fn plan(scenario: &Scenario) -> Result<Self, SslError> {
        let spec = scenario.ssl.clone().unwrap_or_default();
        let problems = spec.check(&scenario.robot_names()).into_vec();
        if let Some(p) = problems.first() {
            return Err(SslError::Spec(p.to_string()));
        }
        if scenario.world.field.is_none() {
            return Err(SslError::Spec(
                "the scenario has no field ([world.field])".to_string(),
            ));
        }
        Ok(Self {
            teams: team_of_names(&spec, scenario),
            spec,
            handles: HashMap::new(),
        })
    }

    /// The software of the robot `config` describes when the protocol drives it (its cameras
    /// left out with `render_cameras` off); `None` for a robot it does not drive.
    pub fn build(&mut self, config: &RobotConfig) -> Option<Box<dyn RobotSoftware>> {
        let (team, _) = self.teams.get(&config.name)?;
        if !self.spec.protocol_teams.contains(team) {
            return None;
        }
        let mut c = config.clone();
        if !self.spec.render_cameras {
            c.cameras.clear();
        }
        let (remote, handle) = Remote::new(&c, "ssl");
        self.handles.insert(config.name.clone(), handle);
        Some(Box::new(remote))
    }
}

impl SslLink {
    /// The link of `sim`, whose robots' software `software` built.
    pub fn new(sim: &Simulation, mut software: SslSoftware) -> Result<Self, SslError> {
        let scenario = sim.scenario();
        let spec = software.spec.clone();
        let field = scenario.world.field.clone().unwrap_or_default();
        let robots = robots_of(sim, &spec, &software.teams, &mut software.handles);
        let by_id = (robots.iter().enumerate())
            .map(|(k, r)| ((r.team, r.id), k))
            .collect();
        let ball_r = scenario.world.ball.as_ref().map_or(21.5, |b| b.radius_mm);
        Ok(Self {
            vision: OverheadVision::new(&spec.vision, &field, ball_r, scenario.seed),
            referee: RefereeOut::new(&spec.referee),
            spec,
            robots,
            by_id,
            last_geometry_s: None,
            speed: 1.0,
            vision_port: None,
            tallies: Tallies::default(),
        })
    }

    /// The `[ssl]` table it serves.
    pub fn spec(&self) -> &SslSpec {
        &self.spec
    }

    /// The tallies so far.
    pub fn tallies(&self) -> Tallies {
        self.tallies
    }

    /// The score: goals of blue and of yellow.
    pub fn score(&self) -> [u32; 2] {
        self.referee.score
    }

    /// Simulated time over wall time the protocol asked for (1: real time).
    pub fn speed(&self) -> f64 {
        self.speed
    }

    /// The vision port the protocol asked for, if it did.
    pub fn vision_port(&self) -> Option<u16> {
        self.vision_port
    }

    /// The robot `team` `id`, if the scenario has it.
    pub fn robot_agent(&self, team: TeamColor, id: u32) -> Option<usize> {
        self.by_id.get(&(team, id)).map(|&k| self.robots[k].agent)
    }

    /// A datagram to `team`'s robot-control port: its commands taken, the team's feedback and
    /// the errors answered (encoded `RobotControlResponse`).
    pub fn robot_control(&mut self, sim: &Simulation, team: TeamColor, bytes: &[u8]) -> Vec<u8> {
        self.tallies.datagrams += 1;
        let response = match decode::<RobotControl>(bytes, "RobotControl") {
            Ok(c) => self.apply_robot_control(sim, team, &c),
            Err(e) => self.malformed(e, |errors| RobotControlResponse {
                errors,
                feedback: Vec::new(),
            }),
        };
        self.tallies.errors += response.errors.len() as u64;
        response.encode_to_vec()
    }

    /// A datagram to the simulation-control port (encoded `SimulatorResponse`).
    /// A game controller's `Referee` message there (with its `source_identifier` set) sets
    /// the referee's command.
    pub fn simulator_command(&mut self, sim: &mut Simulation, bytes: &[u8]) -> Vec<u8> {
        self.tallies.datagrams += 1;
        let response = match decode(bytes, "SimulatorCommand") {
            Ok(c) => SimulatorResponse {
                errors: self.apply_simulator_command(sim, &c),
            },
            Err(e) => match self.referee_command(sim.world().time_s(), bytes) {
                Some(errors) => SimulatorResponse { errors },
                None => self.malformed(e, |errors| SimulatorResponse { errors }),
            },
        };
        self.tallies.errors += response.errors.len() as u64;
        response.encode_to_vec()
    }

    /// A `Referee` message to the control port: its command taken (the errors: none, or
    /// that it is no command); `None` when the datagram is not one.
    fn referee_command(&mut self, now: f64, bytes: &[u8]) -> Option<Vec<SimulatorError>> {
        let r = decode::<Referee>(bytes, "Referee").ok()?;
        r.source_identifier.as_ref()?;
        if Command::try_from(r.command).is_err() {
            return Some(vec![error(
                "INVALID_REFEREE_COMMAND",
                format!(
                    "referee command {} is not one of the game controller's",
                    r.command
                ),
            )]);
        }
        self.referee.set_command(r.command, now);
        Some(Vec::new())
    }

    /// A decoded `SimulatorCommand` (inside a lockstep request): the errors.
    pub fn command_errors(
        &mut self,
        sim: &mut Simulation,
        c: &super::wire::sim::SimulatorCommand,
    ) -> Vec<SimulatorError> {
        let errors = self.apply_simulator_command(sim, c);
        self.tallies.errors += errors.len() as u64;
        errors
    }

    /// A decoded `RobotControl` of `team` (inside a lockstep request): the errors.
    pub fn control_errors(
        &mut self,
        sim: &Simulation,
        team: TeamColor,
        c: &RobotControl,
    ) -> Vec<SimulatorError> {
        let errors = self.apply_robot_control(sim, team, c).errors;
        self.tallies.errors += errors.len() as u64;
        errors
    }

    /// The feedback of `team`'s robots on the field now.
    pub fn team_feedback(&self, sim: &Simulation, team: TeamColor) -> Vec<RobotFeedback> {
        self.feedback(sim, team)
    }

    pub(crate) fn malformed<R>(
        &mut self,
        e: WireError,
        wrap: impl Fn(Vec<SimulatorError>) -> R,
    ) -> R {
        self.tallies.malformed += 1;
        let code = match e {
            WireError::TooLong { .. } => "DATAGRAM_TOO_LONG",
            WireError::Malformed { .. } => "MALFORMED",
        };
        wrap(vec![error(code, e.to_string())])
    }

    /// Takes a team's commands; the team's feedback and the errors.
    pub(crate) fn apply_robot_control(
        &mut self,
        sim: &Simulation,
        team: TeamColor,
        c: &RobotControl,
    ) -> RobotControlResponse {
        let mut errors = Vec::new();
        if !self.spec.protocol_teams.contains(&team) {
            errors.push(error(
                "TEAM_NOT_REMOTE",
                format!(
                    "the {} team runs omniloop's software here ([ssl] protocol_teams)",
                    team.name()
                ),
            ));
        } else {
            for cmd in &c.robot_commands {
                let who = format!("{} {}", team.name(), cmd.id);
                let Some(&k) = self.by_id.get(&(team, cmd.id)) else {
                    errors.push(error(
                        "UNKNOWN_ROBOT",
                        format!(
                            "{who}: no such robot in the scenario ([ssl] {})",
                            team.name()
                        ),
                    ));
                    continue;
                };
                let judged = judge(cmd, &who, &self.robots[k].abilities);
                errors.extend(self.take_command(sim.world().time_s(), k, judged, &who));
            }
        }
        RobotControlResponse {
            errors,
            feedback: self.feedback(sim, team),
        }
    }

    /// Hands robot `k` a judged command; errors for a robot off the field.
    fn take_command(&mut self, now: f64, k: usize, j: Judged, who: &str) -> Vec<SimulatorError> {
        let r = &mut self.robots[k];
        let mut errors = j.errors;
        if !r.present {
            errors.push(error(
                "ROBOT_ABSENT",
                format!("{who} is off the field (teleport it with present = true)"),
            ));
            return errors;
        }
        let Some(handle) = &r.remote else {
            return errors;
        };
        r.heard_s = Some(now);
        if let Some(d) = j.drive {
            r.drive = d;
        }
        let mut m = handle.lock();
        if r.abilities.max_kick_mm_s.is_some() {
            let (speed_mm_s, angle_rad) = j.kick.unwrap_or((0.0, 0.0));
            m.actuators.push(ActuatorCommand::Kick {
                speed_mm_s,
                angle_rad,
            });
            if let Some(rpm) = j.dribbler_rpm {
                m.actuators.push(ActuatorCommand::Dribble { rpm });
            }
        } else if j.dribbler_rpm.is_some_and(|rpm| rpm > 0.0) {
            errors.push(error(
                "NO_KICKER",
                format!("{who} has no dribbler ([robot.kicker]): the dribbler speed is ignored"),
            ));
        }
        errors
    }

    /// The feedback of `team`'s robots on the field: their light barriers.
    pub(crate) fn feedback(&self, sim: &Simulation, team: TeamColor) -> Vec<RobotFeedback> {
        (self.robots.iter())
            .filter(|r| r.team == team && r.present)
            .map(|r| RobotFeedback {
                id: r.id,
                dribbler_ball_contact: Some(sim.world().light_barrier(r.body)),
                custom: None,
            })
            .collect()
    }

    /// Before a control cycle of `sim`: the drives held, timed out or turned into the robots'
    /// frames; the overhead cameras capture when their cycle is due.
    pub fn before_cycle(&mut self, sim: &Simulation) {
        let t = sim.world().time_s();
        self.hand_drives(sim, t);
        if sim
            .cycle()
            .is_multiple_of(u64::from(self.spec.vision.every_cycles))
        {
            let capture = self.capture(sim, t);
            self.vision.capture(&capture);
        }
    }

    /// After a control cycle of `sim`: what vision and the referee send.
    pub fn after_cycle(&mut self, sim: &Simulation) -> Outgoing {
        let now = sim.world().time_s();
        let mut out = Outgoing {
            t_s: now,
            ..Outgoing::default()
        };
        let geometry_due = (self.last_geometry_s)
            .is_none_or(|g| now - g >= self.spec.vision.geometry_period_s - 1e-9);
        if geometry_due {
            self.last_geometry_s = Some(now);
            out.vision
                .push(wrapper(None, Some(self.vision.geometry().clone())));
        }
        for f in self.vision.due(now) {
            out.vision.push(wrapper(Some(f.clone()), None));
            out.detections.push(f);
        }
        let events = sim.world().ball_events();
        out.referee = (self.referee.update(now, events)).map(|r| r.encode_to_vec());
        out
    }

    /// Each protocol robot's drive into its software's mailbox: stopped after the timeout, a
    /// field-frame velocity turned into the robot's frame by its heading now.
    fn hand_drives(&mut self, sim: &Simulation, t: f64) {
        let timeout = self.spec.command_timeout_s;
        for r in &mut self.robots {
            let Some(handle) = &r.remote else { continue };
            let mut m = handle.lock();
            if r.heard_s.is_some_and(|h| t - h > timeout + 1e-9) {
                r.drive = Drive::Stop;
                r.heard_s = None;
                if r.abilities.max_kick_mm_s.is_some() {
                    m.actuators.push(ActuatorCommand::Dribble { rpm: 0.0 });
                    m.actuators.push(ActuatorCommand::Kick {
                        speed_mm_s: 0.0,
                        angle_rad: 0.0,
                    });
                }
            }
            let heading = sim.world().robot_state(r.body).pose.rotation.angle();
            m.command = match (r.present, r.drive) {
                (false, _) | (_, Drive::Stop) => BodyCommand::STOP,
                (true, Drive::Local(v, w)) => BodyCommand {
                    v_mm_s: v,
                    omega_rad_s: w,
                },
                (true, Drive::Global(v, w)) => BodyCommand {
                    v_mm_s: Rotation2::new(-heading) * v,
                    omega_rad_s: w,
                },
            };
        }
    }

    /// The world as the overhead cameras see it now.
    fn capture(&self, sim: &Simulation, t: f64) -> Capture {
        let world = sim.world();
        let robots = (self.robots.iter())
            .filter(|r| r.present)
            .map(|r| {
                let pose = world.robot_state(r.body).pose;
                SeenRobot {
                    team: r.team,
                    id: r.id,
                    at_mm: pose.translation.vector.into(),
                    heading_rad: pose.rotation.angle(),
                    radius_mm: r.radius_mm,
                    height_mm: r.height_mm,
                }
            })
            .collect();
        let ball_mm = world
            .ball()
            .map(|(_, s)| Point3::new(s.position_mm.x, s.position_mm.y, s.height_mm));
        Capture {
            t_s: t,
            robots,
            ball_mm,
        }
    }

    /// Where absent robot `k` waits: off the floor, beyond the field's walls.
    pub(crate) fn parking(&self, sim: &Simulation, k: usize) -> Isometry2<f64> {
        let f = sim.scenario().world.field.clone().unwrap_or_default();
        let y = f.half_width_mm + f.boundary_width_mm + 2000.0;
        Isometry2::new(Vector2::new(-5000.0 + 400.0 * k as f64, y), 0.0)
    }
}

/// A wrapper packet, encoded.
fn wrapper(
    detection: Option<DetectionFrame>,
    geometry: Option<super::wire::vision::GeometryData>,
) -> Vec<u8> {
    WrapperPacket {
        detection,
        geometry,
        source: None,
    }
    .encode_to_vec()
}

/// Each robot's team and id by name.
fn team_of_names(spec: &SslSpec, s: &Scenario) -> HashMap<String, (TeamColor, u32)> {
    let mut out = HashMap::new();
    for team in TeamColor::BOTH {
        for (id, name) in spec
            .team_names(team, &s.robot_names())
            .into_iter()
            .enumerate()
        {
            out.insert(name, (team, id as u32));
        }
    }
    out
}

/// The teams' robots, in the simulation's order.
fn robots_of(
    sim: &Simulation,
    spec: &SslSpec,
    teams: &HashMap<String, (TeamColor, u32)>,
    handles: &mut HashMap<String, RemoteHandle>,
) -> Vec<SslRobot> {
    let bodies = sim.scenario().robot_bodies();
    let mut out = Vec::new();
    for (k, a) in sim.robots().iter().enumerate() {
        let Some(&(team, id)) = teams.get(a.name()) else {
            continue;
        };
        let body = &bodies[a.body()];
        out.push(SslRobot {
            team,
            id,
            agent: k,
            body: a.body(),
            remote: handles.remove(a.name()),
            drive: Drive::Stop,
            heard_s: None,
            present: true,
            abilities: Abilities {
                max_speed_mm_s: body.max_speed_mm_s,
                max_kick_mm_s: body.kicker.map(|k| k.max_kick_mm_s),
                wheel_angles_rad: spec.wheel_angles_deg.map(f64::to_radians),
                wheel_radius_mm: body.radius_mm * 0.9,
            },
            radius_mm: body.radius_mm,
            height_mm: body.height_mm,
        });
    }
    out
}

/// A scenario as a Small-Size simulator (see the module's documentation): its simulation and
/// the protocol's [`SslLink`] beside it.
pub struct SslSimulator {
    sim: Simulation,
    link: SslLink,
}

impl SslSimulator {
    /// Builds the game of a validated scenario: the protocol's teams on [`Remote`] software,
    /// the others on the built-in stack.
    pub fn new(scenario: &Scenario, options: &RunOptions) -> Result<Self, SslError> {
        let mut software = SslSoftware::plan(scenario)?;
        let sim = Simulation::with_software(
            scenario,
            options,
            |config| match software.build(config) {
                Some(remote) => Ok(remote),
                None => builtin_software(config),
            },
            |_| {},
        )?;
        let link = SslLink::new(&sim, software)?;
        Ok(Self { sim, link })
    }

    /// The simulation being served.
    pub fn simulation(&self) -> &Simulation {
        &self.sim
    }

    /// The protocol's side.
    pub fn link(&self) -> &SslLink {
        &self.link
    }

    /// The `[ssl]` table it serves.
    pub fn spec(&self) -> &SslSpec {
        self.link.spec()
    }

    /// Simulated time now, s.
    pub fn time_s(&self) -> f64 {
        self.sim.world().time_s()
    }

    /// The tallies so far.
    pub fn tallies(&self) -> Tallies {
        self.link.tallies()
    }

    /// The score: goals of blue and of yellow.
    pub fn score(&self) -> [u32; 2] {
        self.link.score()
    }

    /// Simulated time over wall time the protocol asked for (1: real time).
    pub fn speed(&self) -> f64 {
        self.link.speed()
    }

    /// The vision port the protocol asked for, if it did.
    pub fn vision_port(&self) -> Option<u16> {
        self.link.vision_port()
    }

    /// A datagram to `team`'s robot-control port (see [`SslLink::robot_control`]).
    pub fn robot_control(&mut self, team: TeamColor, bytes: &[u8]) -> Vec<u8> {
        self.link.robot_control(&self.sim, team, bytes)
    }

    /// A datagram to the simulation-control port (see [`SslLink::simulator_command`]).
    pub fn simulator_command(&mut self, bytes: &[u8]) -> Vec<u8> {
        self.link.simulator_command(&mut self.sim, bytes)
    }

    /// A decoded `SimulatorCommand`: the errors.
    pub fn command_errors(
        &mut self,
        c: &super::wire::sim::SimulatorCommand,
    ) -> Vec<SimulatorError> {
        self.link.command_errors(&mut self.sim, c)
    }

    /// A decoded `RobotControl` of `team`: the errors.
    pub fn control_errors(&mut self, team: TeamColor, c: &RobotControl) -> Vec<SimulatorError> {
        self.link.control_errors(&self.sim, team, c)
    }

    /// The feedback of `team`'s robots on the field now.
    pub fn team_feedback(&self, team: TeamColor) -> Vec<RobotFeedback> {
        self.link.team_feedback(&self.sim, team)
    }

    /// One control cycle: the drives handed over and the overhead cameras' capture; every
    /// robot's cameras rendered and its software deciding; the world moving on. What vision
    /// and the referee send after it.
    pub fn step(&mut self) -> Result<Outgoing, SslError> {
        self.link.before_cycle(&self.sim);
        self.sim.step()?;
        Ok(self.link.after_cycle(&self.sim))
    }

    /// Ends the game: the run's records, as any run's.
    pub fn finish(mut self, wall_time_s: f64) -> RunOutput {
        self.sim.record_final_state();
        self.sim.finish(wall_time_s)
    }
}

/// What the server (`Server` of the `server` module) serves: a simulation with its [`SslLink`].
/// [`SslSimulator`] is one; a host that owns its simulation otherwise (a session of the
/// Python package) is another.
pub trait SslHost {
    /// The simulation.
    fn simulation(&self) -> &Simulation;
    /// The protocol's side.
    fn link(&self) -> &SslLink;
    /// A datagram to `team`'s robot-control port, answered.
    fn robot_control(&mut self, team: TeamColor, bytes: &[u8]) -> Vec<u8>;
    /// A datagram to the simulation-control port, answered.
    fn simulator_command(&mut self, bytes: &[u8]) -> Vec<u8>;
    /// A decoded `SimulatorCommand`: the errors.
    fn command_errors(&mut self, c: &super::wire::sim::SimulatorCommand) -> Vec<SimulatorError>;
    /// A decoded `RobotControl` of `team`: the errors.
    fn control_errors(&mut self, team: TeamColor, c: &RobotControl) -> Vec<SimulatorError>;
    /// One control cycle with the link around it.
    fn step(&mut self) -> Result<Outgoing, SslError>;
}

impl SslHost for SslSimulator {
    fn simulation(&self) -> &Simulation {
        &self.sim
    }

    fn link(&self) -> &SslLink {
        &self.link
    }

    fn robot_control(&mut self, team: TeamColor, bytes: &[u8]) -> Vec<u8> {
        SslSimulator::robot_control(self, team, bytes)
    }

    fn simulator_command(&mut self, bytes: &[u8]) -> Vec<u8> {
        SslSimulator::simulator_command(self, bytes)
    }

    fn command_errors(&mut self, c: &super::wire::sim::SimulatorCommand) -> Vec<SimulatorError> {
        SslSimulator::command_errors(self, c)
    }

    fn control_errors(&mut self, team: TeamColor, c: &RobotControl) -> Vec<SimulatorError> {
        SslSimulator::control_errors(self, team, c)
    }

    fn step(&mut self) -> Result<Outgoing, SslError> {
        SslSimulator::step(self)
    }
}
