//! `omniloop.Simulation`: a run stepped from Python, with Python as the robot's software (or
//! the built-in stack), and the `Observation` it gives each step.
//!
//! The robot's side and the simulator's side stay apart: an `Observation` holds only what the
//! robot's own sensors give (frames, odometry with its errors, actuator state) and what it
//! works out from them (dead reckoning from the start it is told); the truth comes from
//! `Simulation.truth()`, for scoring and recording.

use crate::convert::{finite_numbers, json_to_py, rgb_array, rgb_image_array};
use crate::errors::{RunFinishedError, run_error};
use crate::freespace::PyFreeSpaceDetector;
use crate::scenario::PyScenario;
use crate::ssl::{Engine, engine};
use crate::truth::truth_frame_dict;
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop::control::DeadReckoning;
use omniloop::robot::perception::FreeSpaceStage;
use omniloop::robot::{ActuatorCommand, ActuatorState, BodyCommand, Remote, RemoteHandle};
use omniloop::run::record::estimates_line;
use omniloop::run::{RunError, RunOptions};
use omniloop::scenario::PilotChoice;
use omniloop::vision::FreeSpaceConfig;
use omniloop::{Scenario, Session, Truth};
use omniloop_sim::RendererChoice;
use omniloop_sim::render::BatchHandle;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard, PoisonError};

/// Which software drives the robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Driver {
    /// Python, through `step(command)`.
    Python,
    /// The built-in stack, as `omniloop run` runs it.
    Builtin,
    /// The Small-Size League's simulation protocol: a team's AI on `omniloop ssl`'s ports
    /// (the scenario's `[ssl]`); a robot of a team the protocol does not drive runs the
    /// built-in stack.
    Ssl,
}

impl Driver {
    pub fn parse(robot: &str) -> PyResult<Self> {
        match robot {
            "python" => Ok(Self::Python),
            "builtin" => Ok(Self::Builtin),
            "ssl" => Ok(Self::Ssl),
            other => Err(PyValueError::new_err(format!(
                "robot={other:?}: expected \"python\" (your commands), \"builtin\" (the \
                 scenario's own robot software) or \"ssl\" (a team's AI over the SSL \
                 simulation protocol)"
            ))),
        }
    }
}

/// Who drives each robot, as Python names it: one word for every robot (`robot="python"`),
/// or a dict naming every robot of a team (`robot={"blue1": "python", "blue2": "builtin"}`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Drivers {
    /// The same software on every robot.
    All(Driver),
    /// Each robot's, by name.
    Named(Vec<(String, Driver)>),
}

impl Drivers {
    /// Reads `robot=`: a word or a dict of words.
    pub fn parse(robot: &Bound<'_, PyAny>) -> PyResult<Self> {
        if let Ok(word) = robot.extract::<String>() {
            return Ok(Self::All(Driver::parse(&word)?));
        }
        let dict = robot.cast::<PyDict>().map_err(|_| {
            PyValueError::new_err(
                "robot= is \"python\", \"builtin\" or a dict {robot name: \"python\" or \
                 \"builtin\"} naming every robot of the team",
            )
        })?;
        let mut named = Vec::with_capacity(dict.len());
        for (k, v) in dict.iter() {
            let name: String = k
                .extract()
                .map_err(|_| PyValueError::new_err("robot=: every key is a robot's name (str)"))?;
            let word: String = v.extract().map_err(|_| {
                PyValueError::new_err(format!(
                    "robot={{{name:?}: ...}}: \"python\" or \"builtin\""
                ))
            })?;
            named.push((name, Driver::parse(&word)?));
        }
        Ok(Self::Named(named))
    }

    /// Each robot's driver, in the order of `names`; a name that is no robot's, or a robot
    /// left without software, is refused.
    pub fn resolve(&self, scenario: &str, names: &[String]) -> PyResult<Vec<Driver>> {
        let named = match self {
            Self::All(d) => return Ok(vec![*d; names.len()]),
            Self::Named(named) => named,
        };
        if let Some((stranger, _)) = named.iter().find(|(n, _)| !names.contains(n)) {
            return Err(PyValueError::new_err(format!(
                "robot={{{stranger:?}: ...}}: scenario {scenario:?} has no robot of that name \
                 (its robots: {})",
                names.join(", ")
            )));
        }
        names
            .iter()
            .map(|name| {
                named
                    .iter()
                    .find(|(n, _)| n == name)
                    .map(|(_, d)| *d)
                    .ok_or_else(|| {
                        PyValueError::new_err(format!(
                            "robot {name:?} has no software: name it in robot={{...}} with \
                             \"python\" (your commands) or \"builtin\" (the scenario's stack)"
                        ))
                    })
            })
            .collect()
    }
}

pub use crate::convert::renderer_choice;

/// What Python hands one step: checked before the step runs.
#[derive(Debug, Clone, Default)]
pub struct Command {
    body: BodyCommand,
    actuators: Vec<ActuatorCommand>,
    estimate: Option<Isometry2<f64>>,
}

/// What the robot's side keeps of one robot between steps.
struct Member {
    name: String,
    /// Where Python's commands go, when Python drives it.
    remote: Option<RemoteHandle>,
    dead_reckoning: DeadReckoning,
    start: Isometry2<f64>,
    differential: bool,
    pan_sensors: Vec<String>,
    sensors: Vec<String>,
    /// Its kicker and dribbler, when it has them.
    kicker: Option<omniloop_sim::KickerSpec>,
}

/// What a run traces beyond what the robots' software reads.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Extras {
    /// Vision's camera is rendered and calibrated whatever the software reads.
    pub frames: bool,
    /// Each frame's truth is traced beside it (the simulator's side only).
    pub truth: bool,
}

/// Why `other` cannot stand in for `base` in a run already stepped from Python: the robots
/// (names, cameras and their sizes, drive, kicker) must be the same; where they start, the
/// world and the ball may differ.
pub fn same_shape(base: &Scenario, other: &Scenario) -> Result<(), String> {
    let (names, others) = (base.robot_names(), other.robot_names());
    if names != others {
        return Err(format!(
            "scenario {:?} has robots {others:?}, this run {names:?}",
            other.name
        ));
    }
    for ((a, b), name) in base.members().iter().zip(other.members()).zip(&names) {
        let cams = |s: &Scenario| -> Vec<(String, u32, u32)> {
            let r = &s.robot.sensors;
            r.iter()
                .map(|c| (c.name.clone(), c.width_px, c.height_px))
                .collect()
        };
        let what = if cams(a) != cams(&b) {
            Some("cameras (names and sizes)")
        } else if a.robot.differential.is_some() != b.robot.differential.is_some() {
            Some("drive")
        } else if a.robot.kicker.is_some() != b.robot.kicker.is_some() {
            Some("kicker")
        } else {
            None
        };
        if let Some(what) = what {
            return Err(format!(
                "scenario {:?}: robot {name:?} has other {what} than in this run",
                other.name
            ));
        }
    }
    Ok(())
}

/// One run being stepped, with what the robots' side keeps between steps.
pub struct State {
    engine: Engine,
    members: Vec<Member>,
    team: bool,
    seed: u64,
}

impl State {
    /// Builds the run of `scenario` with `seed`, each robot driven by its entry of `drivers`
    /// (in the scenario's order of robots), and senses its first frames; `extras` says what
    /// else it traces (vision's camera whatever the software reads, the truth beside frames).
    pub fn new(
        scenario: &Scenario,
        seed: u64,
        renderer: RendererChoice,
        drivers: &[Driver],
        shared_gpu: Option<BatchHandle>,
        extras: Extras,
    ) -> Result<Self, RunError> {
        let mut scenario = scenario.clone();
        scenario.seed = seed;
        if drivers.contains(&Driver::Python) {
            // Python is the robot's software: it drives, whatever pilot the file names.
            scenario.run.pilot = PilotChoice::Robot;
        }
        let options = RunOptions {
            renderer,
            shared_gpu,
            takes_frames: extras.frames,
            truth: extras.truth,
            ..RunOptions::default()
        };
        let names = scenario.robot_names();
        let mut remotes: Vec<Option<RemoteHandle>> = vec![None; names.len()];
        let served = drivers.contains(&Driver::Ssl);
        let engine = engine(&scenario, &options, served, |config| {
            let k = names.iter().position(|n| *n == config.name).unwrap_or(0);
            match drivers.get(k).copied().unwrap_or(Driver::Builtin) {
                Driver::Python => {
                    let (software, handle) = Remote::new(config, "python");
                    remotes[k] = Some(handle);
                    Ok(Box::new(software))
                }
                Driver::Builtin | Driver::Ssl => omniloop::run::builtin_software(config),
            }
        })?;
        let members = scenario
            .members()
            .iter()
            .zip(names)
            .zip(remotes)
            .map(|((m, name), remote)| Member {
                name,
                remote,
                dead_reckoning: DeadReckoning::new(),
                start: m.start().isometry(),
                differential: m.robot.differential.is_some(),
                pan_sensors: m
                    .robot
                    .sensors
                    .iter()
                    .filter(|s| s.optics.pinhole().is_some())
                    .map(|s| s.name.clone())
                    .collect(),
                sensors: m.robot.sensors.iter().map(|s| s.name.clone()).collect(),
                kicker: m.robot.kicker,
            })
            .collect();
        Ok(Self {
            engine,
            members,
            team: scenario.is_team(),
            seed,
        })
    }

    /// One control cycle with `command` (the one robot's, when Python drives it).
    pub fn step(&mut self, command: Option<Command>) -> Result<(), RunError> {
        self.step_all(vec![command])
    }

    /// One control cycle with each robot's command (in the robots' order; `None` for a robot
    /// the built-in software drives), and the odometry it brings.
    pub fn step_all(&mut self, commands: Vec<Option<Command>>) -> Result<(), RunError> {
        for (m, c) in self.members.iter().zip(commands) {
            if let (Some(remote), Some(c)) = (&m.remote, c) {
                let mut mail = remote.lock();
                mail.command = c.body;
                mail.actuators = c.actuators;
                mail.estimate = c.estimate;
            }
        }
        self.engine.step()?;
        let sim = self.engine.session().simulation();
        for (m, a) in self.members.iter_mut().zip(sim.robots()) {
            if let Some(r) = a.last_odometry() {
                m.dead_reckoning
                    .update(r.v_body_mm_s, r.omega_rad_s, r.dt_s);
            }
        }
        Ok(())
    }

    /// Whether the run is over.
    pub fn done(&self) -> bool {
        self.engine.session().finished()
    }

    /// The truth now (the first robot's).
    pub fn truth(&self) -> Truth {
        self.engine.session().simulation().truth()
    }

    /// Robot `k`'s truth now.
    fn truth_of(&self, k: usize) -> Option<Truth> {
        self.engine.session().simulation().truth_of(k)
    }

    /// The session.
    pub fn session(&self) -> &Session {
        self.engine.session()
    }

    /// Where the protocol's ports are, when served over it.
    pub fn ssl_ports(&self) -> Option<omniloop::ssl::Bound> {
        self.engine.ports().copied()
    }

    /// The session, to change the world between steps.
    pub fn session_mut(&mut self) -> &mut Session {
        self.engine.session_mut()
    }

    /// The seed of this run.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Whether the scenario is a team's.
    pub fn is_team(&self) -> bool {
        self.team
    }

    /// The robots' names, in order.
    pub fn names(&self) -> Vec<String> {
        self.members.iter().map(|m| m.name.clone()).collect()
    }

    /// The index of the robot called `name` (the first when `None`).
    fn robot_index(&self, name: Option<&str>) -> PyResult<usize> {
        let Some(name) = name else { return Ok(0) };
        self.members
            .iter()
            .position(|m| m.name == name)
            .ok_or_else(|| {
                PyValueError::new_err(format!(
                    "no robot {name:?} (robots: {})",
                    self.names().join(", ")
                ))
            })
    }

    /// Where dead reckoning puts robot `k` (world frame, from the start it is told).
    fn odometry_pose(&self, k: usize) -> Isometry2<f64> {
        let m = &self.members[k];
        m.start * m.dead_reckoning.pose()
    }

    /// The one robot's command (see [`State::command_of`]).
    pub fn command(
        &self,
        command: &Bound<'_, PyAny>,
        actuators: Option<&Bound<'_, PyAny>>,
        estimate: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Command> {
        self.command_of(0, command, actuators, estimate)
    }

    /// Robot `k`'s command from Python, checked against that robot: `(vx_mm_s, vy_mm_s,
    /// omega_rad_s)`, or `(v_mm_s, omega_rad_s)` for a differential drive; pan commands for
    /// cameras on pan units; an estimate `(x_mm, y_mm, theta_rad)`.
    fn command_of(
        &self,
        k: usize,
        command: &Bound<'_, PyAny>,
        actuators: Option<&Bound<'_, PyAny>>,
        estimate: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Command> {
        let body = if self.members[k].differential {
            let v = finite_numbers("command", command, "v_mm_s, omega_rad_s")?;
            let [speed, omega] = v[..] else {
                return Err(PyValueError::new_err(format!(
                    "command has {} numbers: a differential robot takes (v_mm_s, omega_rad_s)",
                    v.len()
                )));
            };
            BodyCommand {
                v_mm_s: Vector2::new(speed, 0.0),
                omega_rad_s: omega,
            }
        } else {
            let v = finite_numbers("command", command, "vx_mm_s, vy_mm_s, omega_rad_s")?;
            let [vx, vy, omega] = v[..] else {
                return Err(PyValueError::new_err(format!(
                    "command has {} numbers: an omnidirectional robot takes (vx_mm_s, vy_mm_s, \
                     omega_rad_s) in its body frame",
                    v.len()
                )));
            };
            BodyCommand {
                v_mm_s: Vector2::new(vx, vy),
                omega_rad_s: omega,
            }
        };
        let actuators = match actuators {
            Some(a) if !a.is_none() => self.actuator_commands(k, a)?,
            _ => Vec::new(),
        };
        let estimate = match estimate {
            Some(e) if !e.is_none() => {
                let v = finite_numbers("estimate", e, "x_mm, y_mm, theta_rad")?;
                let [x, y, theta] = v[..] else {
                    return Err(PyValueError::new_err(
                        "estimate must be (x_mm, y_mm, theta_rad) in the world frame",
                    ));
                };
                Some(Isometry2::new(Vector2::new(x, y), theta))
            }
            _ => None,
        };
        Ok(Command {
            body,
            actuators,
            estimate,
        })
    }

    /// Pan commands: a list of dicts `{"sensor": NAME, "pan_rad": A}` (pan toward A) or
    /// `{"sensor": NAME, "rate_rad_s": W}` (pan at W until told otherwise); the kicker's and
    /// dribbler's: `{"kick_mm_s": S, "angle_rad": A}` (a kick, armed until it fires; `angle_rad`
    /// optional, 0 flat) and `{"dribbler_rpm": R}`.
    fn actuator_commands(
        &self,
        k: usize,
        list: &Bound<'_, PyAny>,
    ) -> PyResult<Vec<ActuatorCommand>> {
        let member = &self.members[k];
        let shape = "actuators must be a list of dicts {\"sensor\": NAME, \"pan_rad\": A}, \
                     {\"sensor\": NAME, \"rate_rad_s\": W}, {\"kick_mm_s\": S, \"angle_rad\": A} \
                     or {\"dribbler_rpm\": R}";
        let items: Vec<Bound<'_, PyDict>> =
            list.extract().map_err(|_| PyValueError::new_err(shape))?;
        let mut out = Vec::with_capacity(items.len());
        for item in items {
            if let Some(c) = ball_command(member, &item, shape)? {
                out.push(c);
                continue;
            }
            let sensor: String = item
                .get_item("sensor")?
                .ok_or_else(|| PyValueError::new_err(shape))?
                .extract()
                .map_err(|_| PyValueError::new_err(shape))?;
            if !member.pan_sensors.contains(&sensor) {
                return Err(PyValueError::new_err(format!(
                    "actuators: no pan unit carries camera {sensor:?} (cameras: {:?}; only \
                     pinhole cameras are on pan units: {:?})",
                    member.sensors, member.pan_sensors
                )));
            }
            let number = |key: &str| -> PyResult<Option<f64>> {
                match item.get_item(key)? {
                    Some(v) => {
                        let x: f64 = v.extract().map_err(|_| PyValueError::new_err(shape))?;
                        if !x.is_finite() {
                            return Err(PyValueError::new_err(format!(
                                "actuators: {key} of {sensor:?} is {x}: it must be finite"
                            )));
                        }
                        Ok(Some(x))
                    }
                    None => Ok(None),
                }
            };
            out.push(match (number("pan_rad")?, number("rate_rad_s")?) {
                (Some(pan_rad), None) => ActuatorCommand::PanTo { sensor, pan_rad },
                (None, Some(rate_rad_s)) => ActuatorCommand::PanAt { sensor, rate_rad_s },
                _ => return Err(PyValueError::new_err(shape)),
            });
        }
        Ok(out)
    }
}

/// A kicker's or dribbler's command of `item`, checked against the robot's kicker; `None` when
/// `item` is no such command.
fn ball_command(
    member: &Member,
    item: &Bound<'_, PyDict>,
    shape: &str,
) -> PyResult<Option<ActuatorCommand>> {
    let number = |key: &str| -> PyResult<Option<f64>> {
        item.get_item(key)?
            .map(|v| {
                v.extract::<f64>()
                    .map_err(|_| PyValueError::new_err(shape.to_string()))
            })
            .transpose()
    };
    let (kick, rpm) = (number("kick_mm_s")?, number("dribbler_rpm")?);
    if kick.is_none() && rpm.is_none() {
        return Ok(None);
    }
    let Some(spec) = &member.kicker else {
        return Err(PyValueError::new_err(format!(
            "actuators: robot {:?} has no kicker and dribbler ([robot.kicker])",
            member.name
        )));
    };
    if let Some(rpm) = rpm {
        if !(rpm.is_finite() && rpm >= 0.0) {
            return Err(PyValueError::new_err(format!(
                "actuators: dribbler_rpm is {rpm}: it must be a finite number >= 0"
            )));
        }
        return Ok(Some(ActuatorCommand::Dribble { rpm }));
    }
    let kick = omniloop_sim::Kick {
        speed_mm_s: kick.unwrap_or_default(),
        angle_rad: number("angle_rad")?.unwrap_or(0.0),
    };
    if let Some(why) = kick.problem(spec) {
        return Err(PyValueError::new_err(format!("actuators: {why}")));
    }
    Ok(Some(ActuatorCommand::Kick {
        speed_mm_s: kick.speed_mm_s,
        angle_rad: kick.angle_rad,
    }))
}

/// What the wheel encoders measured over the last period, with the scenario's errors.
#[pyclass(module = "omniloop", name = "Odometry", frozen, get_all)]
#[derive(Debug, Clone, Copy)]
pub struct Odometry {
    /// Body-frame velocity, x (forward), mm/s.
    vx_mm_s: f64,
    /// Body-frame velocity, y (left), mm/s.
    vy_mm_s: f64,
    /// Rotation rate, rad/s (counter-clockwise positive).
    omega_rad_s: f64,
    /// The period it covers, s (0 before the first step).
    dt_s: f64,
}

#[pymethods]
impl Odometry {
    fn __repr__(&self) -> String {
        format!(
            "Odometry(vx_mm_s={}, vy_mm_s={}, omega_rad_s={}, dt_s={})",
            self.vx_mm_s, self.vy_mm_s, self.omega_rad_s, self.dt_s
        )
    }
}

/// What the robot's sensors give at the start of a control cycle.
#[pyclass(module = "omniloop", name = "Observation", frozen)]
pub struct Observation {
    /// Time of the cycle, s.
    #[pyo3(get)]
    t_s: f64,
    /// Control cycles run before it.
    #[pyo3(get)]
    cycle: u64,
    /// Sensor name -> `H x W x 3` `uint8` image.
    #[pyo3(get)]
    frames: Py<PyDict>,
    /// The last odometry reading.
    #[pyo3(get)]
    odometry: Py<Odometry>,
    /// Where dead reckoning of the odometry puts the robot, from the start it is told:
    /// `(x_mm, y_mm, theta_rad)` in the world frame.
    #[pyo3(get)]
    odometry_pose: (f64, f64, f64),
    /// Camera name -> pan angle, rad, for cameras on pan units.
    #[pyo3(get)]
    actuators: Py<PyDict>,
    /// The dribbler's light barrier: whether it sees the ball (`None` without a kicker).
    #[pyo3(get)]
    ball_in_dribbler: Option<bool>,
    /// Whether the run is over (time up, or the goal reached where the run stops there).
    #[pyo3(get)]
    done: bool,
    /// With `robot="builtin"`: the last cycle's `estimates.jsonl` line, read into a dict only
    /// when asked for.
    record: Option<String>,
}

#[pymethods]
impl Observation {
    /// With `robot="builtin"`: what the robot believed after the last cycle (its
    /// `estimates.jsonl` record without the truth); `None` otherwise.
    #[getter]
    fn estimates<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(line) = &self.record else {
            return Ok(None);
        };
        let record = json_to_py(py, line)?.cast_into::<PyDict>()?;
        record.del_item("truth")?;
        Ok(Some(record))
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let frames: Vec<String> = self
            .frames
            .bind(py)
            .keys()
            .iter()
            .map(|k| k.to_string())
            .collect();
        format!(
            "Observation(t_s={}, cycle={}, frames={frames:?}, done={})",
            self.t_s, self.cycle, self.done
        )
    }
}

/// The observation of `state` now (its first robot's).
pub fn observation(py: Python<'_>, state: &State) -> PyResult<Observation> {
    observation_of(py, state, 0)
}

/// Robot `k`'s observation of `state` now.
fn observation_of(py: Python<'_>, state: &State, k: usize) -> PyResult<Observation> {
    let sim = state.session().simulation();
    let agent = &sim.robots()[k];
    let frames = PyDict::new(py);
    for f in agent.frames() {
        frames.set_item(f.sensor, rgb_array(py, f.image))?;
    }
    let odometry = match agent.last_odometry() {
        Some(r) => Odometry {
            vx_mm_s: r.v_body_mm_s.x,
            vy_mm_s: r.v_body_mm_s.y,
            omega_rad_s: r.omega_rad_s,
            dt_s: r.dt_s,
        },
        None => Odometry {
            vx_mm_s: 0.0,
            vy_mm_s: 0.0,
            omega_rad_s: 0.0,
            dt_s: 0.0,
        },
    };
    let actuators = PyDict::new(py);
    let mut ball_in_dribbler = None;
    for a in agent.actuator_state(sim.world()) {
        match a {
            ActuatorState::Pan { sensor, pan_rad } => actuators.set_item(sensor, pan_rad)?,
            ActuatorState::Kicker {
                ball_in_dribbler: seen,
                ..
            } => ball_in_dribbler = Some(seen),
        }
    }
    let record = match state.members[k].remote {
        Some(_) => None,
        None => last_line(state, k),
    };
    let p = state.odometry_pose(k);
    Ok(Observation {
        t_s: sim.world().time_s(),
        cycle: sim.cycle(),
        frames: frames.unbind(),
        odometry: Py::new(py, odometry)?,
        odometry_pose: (p.translation.x, p.translation.y, p.rotation.angle()),
        actuators: actuators.unbind(),
        ball_in_dribbler,
        done: state.done(),
        record,
    })
}

/// Every robot's observation by name, for a team; the one robot's observation otherwise.
fn observations(py: Python<'_>, state: &State) -> PyResult<Py<PyAny>> {
    if !state.is_team() {
        return Ok(Py::new(py, observation_of(py, state, 0)?)?.into_any());
    }
    let d = PyDict::new(py);
    for (k, name) in state.names().iter().enumerate() {
        d.set_item(name, Py::new(py, observation_of(py, state, k)?)?)?;
    }
    Ok(d.into_any().unbind())
}

/// Robot `k`'s last `estimates.jsonl` line (truth included), if a cycle ran.
fn last_line(state: &State, k: usize) -> Option<String> {
    let agent = &state.session().simulation().robots()[k];
    let estimates = agent.estimates();
    let i = estimates.len().checked_sub(1)?;
    let floor = agent.floor_scores().get(i).and_then(Option::as_ref);
    Some(estimates_line(&agent.trajectory()[i], &estimates[i], floor))
}

/// Robot `k`'s last `estimates.jsonl` record as a dict (truth included), if a cycle ran.
fn last_record<'py>(
    py: Python<'py>,
    state: &State,
    k: usize,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    last_line(state, k)
        .map(|line| json_to_py(py, &line))
        .transpose()
}

/// `f` of every robot by name, for a team; of the one robot otherwise.
fn per_robot<'py>(
    py: Python<'py>,
    state: &State,
    f: impl Fn(usize) -> PyResult<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    if !state.is_team() {
        return f(0);
    }
    let d = PyDict::new(py);
    for (k, name) in state.names().iter().enumerate() {
        d.set_item(name, f(k)?)?;
    }
    Ok(d.into_any())
}

/// A team's `what` argument of `step()`: a dict by robot name (or nothing); `python` names
/// the robots Python drives, for the message.
fn team_dict<'py>(
    what: &str,
    v: Option<&Bound<'py, PyAny>>,
    python: &[String],
) -> PyResult<Option<Bound<'py, PyDict>>> {
    match v {
        Some(v) if !v.is_none() => v.cast::<PyDict>().map(|d| Some(d.clone())).map_err(|_| {
            PyValueError::new_err(format!(
                "a team's step() takes {what} as a dict {{robot name: ...}} (Python drives: {})",
                python.join(", ")
            ))
        }),
        _ => Ok(None),
    }
}

/// The truth beside each frame robot `k`'s software got in the last cycle, by camera name
/// (empty unless the run traces the truth).
pub fn truth_frames<'py>(py: Python<'py>, state: &State, k: usize) -> PyResult<Bound<'py, PyDict>> {
    let agent = &state.session().simulation().robots()[k];
    let out = PyDict::new(py);
    for (name, t) in agent.truth_frames() {
        out.set_item(name, truth_frame_dict(py, t)?)?;
    }
    Ok(out)
}

/// The message of `truth_frames()` on a run made without the truth.
pub const NO_TRUTH: &str = "truth_frames(): the truth beside the frames is traced only when \
                            asked for: make the simulation with truth=True";

/// The truth as a dict.
pub fn truth_dict<'py>(py: Python<'py>, t: &Truth) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("t_s", t.t_s)?;
    d.set_item("x_mm", t.pose.translation.x)?;
    d.set_item("y_mm", t.pose.translation.y)?;
    d.set_item("theta_rad", t.pose.rotation.angle())?;
    d.set_item("vx_mm_s", t.velocity_mm_s.x)?;
    d.set_item("vy_mm_s", t.velocity_mm_s.y)?;
    d.set_item("omega_rad_s", t.omega_rad_s)?;
    d.set_item("contacts", t.contacts)?;
    d.set_item("reached_goal", t.reached_goal)?;
    d.set_item("targets_reached", t.targets_reached)?;
    if let Some(b) = &t.ball {
        let ball = PyDict::new(py);
        ball.set_item("x_mm", b.position_mm.x)?;
        ball.set_item("y_mm", b.position_mm.y)?;
        ball.set_item("z_mm", b.height_mm)?;
        ball.set_item("vx_mm_s", b.velocity_mm_s.x)?;
        ball.set_item("vy_mm_s", b.velocity_mm_s.y)?;
        ball.set_item("vz_mm_s", b.vz_mm_s)?;
        d.set_item("ball", ball)?;
        d.set_item("ball_in_dribbler", t.ball_in_dribbler)?;
    }
    Ok(d)
}

/// A scenario run stepped from Python.
#[pyclass(module = "omniloop", name = "Simulation")]
pub struct PySimulation {
    scenario: PyScenario,
    renderer: RendererChoice,
    /// Who drives each robot, in the robots' order.
    drivers: Vec<Driver>,
    /// What the run traces beyond what the software reads (vision's camera, the truth).
    extras: Extras,
    state: Mutex<State>,
}

impl PySimulation {
    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The robots Python drives, by name.
    fn driven_by_python(&self, state: &State) -> Vec<String> {
        state
            .names()
            .into_iter()
            .zip(&self.drivers)
            .filter(|(_, d)| **d == Driver::Python)
            .map(|(n, _)| n)
            .collect()
    }

    /// The one robot's checked command for a step.
    fn one_command(
        &self,
        state: &State,
        command: Option<&Bound<'_, PyAny>>,
        actuators: Option<&Bound<'_, PyAny>>,
        estimate: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Vec<Option<Command>>> {
        Ok(vec![match (self.drivers[0], command) {
            (Driver::Python, Some(c)) if !c.is_none() => {
                Some(state.command(c, actuators, estimate)?)
            }
            (Driver::Python, _) => {
                return Err(PyValueError::new_err(
                    "step() needs a command: (vx_mm_s, vy_mm_s, omega_rad_s), or (v_mm_s, \
                     omega_rad_s) for a differential robot",
                ));
            }
            (Driver::Builtin | Driver::Ssl, Some(c)) if !c.is_none() => {
                return Err(PyValueError::new_err(
                    "robot=\"builtin\" (or \"ssl\") decides its own commands: call step() \
                     without one",
                ));
            }
            (Driver::Builtin | Driver::Ssl, _) => None,
        }])
    }

    /// A team's checked commands for a step: `command` (and `actuators`, `estimate`) are
    /// dicts by robot name, holding every robot Python drives and no other.
    fn team_commands(
        &self,
        state: &State,
        command: Option<&Bound<'_, PyAny>>,
        actuators: Option<&Bound<'_, PyAny>>,
        estimate: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Vec<Option<Command>>> {
        let names = state.names();
        let python = self.driven_by_python(state);
        let dict = |what: &str, v| team_dict(what, v, &python);
        let (commands, actuators, estimates) = (
            dict("command", command)?,
            dict("actuators", actuators)?,
            dict("estimate", estimate)?,
        );
        for d in [&commands, &actuators, &estimates].into_iter().flatten() {
            for key in d.keys() {
                let name: String = key.extract().map_err(|_| {
                    PyValueError::new_err("step(): every key is a robot's name (str)")
                })?;
                if !names.contains(&name) {
                    return Err(PyValueError::new_err(format!(
                        "step(): no robot {name:?} (the robots: {})",
                        names.join(", ")
                    )));
                }
                if !python.contains(&name) {
                    return Err(PyValueError::new_err(format!(
                        "step(): robot {name:?} runs the built-in software or the SSL \
                         protocol's commands: give it no command"
                    )));
                }
            }
        }
        let mut out = Vec::with_capacity(names.len());
        for (k, name) in names.iter().enumerate() {
            if self.drivers[k] != Driver::Python {
                out.push(None);
                continue;
            }
            let c = commands
                .as_ref()
                .and_then(|d| d.get_item(name).ok().flatten());
            let Some(c) = c else {
                return Err(PyValueError::new_err(format!(
                    "step(): no command for robot {name:?} (Python drives: {})",
                    python.join(", ")
                )));
            };
            let a = actuators
                .as_ref()
                .and_then(|d| d.get_item(name).ok().flatten());
            let e = estimates
                .as_ref()
                .and_then(|d| d.get_item(name).ok().flatten());
            let cmd = state
                .command_of(k, &c, a.as_ref(), e.as_ref())
                .map_err(|err| {
                    let why = err.value(c.py()).to_string();
                    PyValueError::new_err(format!("robot {name:?}: {why}"))
                })?;
            out.push(Some(cmd));
        }
        Ok(out)
    }
}

#[pymethods]
impl PySimulation {
    /// A run of `scenario` with `seed` (default: the scenario's), the `renderer` (`"cpu"`,
    /// `"gpu"` or `"auto"`) and `robot`: `"python"` (you step it with commands),
    /// `"builtin"` (the scenario's own robot software decides) or `"ssl"` (a team's AI over the
    /// SSL simulation protocol, on the ports of the scenario's `[ssl]`; `ssl_ports()`); for a
    /// team, one of these for every robot or a dict naming each robot's (`{"blue1": "python",
    /// "blue2": "builtin"}`); `frames=True` renders (and calibrates) vision's camera even where the built-in software
    /// reads no frame, to watch it or run a detector on it; `truth=True` traces the truth
    /// beside each frame (`truth_frames()`), the simulator's side only.
    #[new]
    #[pyo3(signature = (
        scenario, seed = None, renderer = "cpu", robot = None, frames = false, truth = false
    ))]
    fn new(
        py: Python<'_>,
        scenario: PyRef<'_, PyScenario>,
        seed: Option<u64>,
        renderer: &str,
        robot: Option<&Bound<'_, PyAny>>,
        frames: bool,
        truth: bool,
    ) -> PyResult<Self> {
        let renderer = renderer_choice(renderer)?;
        let drivers = match robot {
            Some(r) if !r.is_none() => Drivers::parse(r)?,
            _ => Drivers::All(Driver::Python),
        };
        let scenario = scenario.clone();
        let s = &scenario.scenario;
        let drivers = drivers.resolve(&s.name, &s.robot_names())?;
        let seed = seed.unwrap_or(s.seed);
        let extras = Extras { frames, truth };
        let state = py
            .detach(|| State::new(s, seed, renderer, &drivers, None, extras))
            .map_err(run_error)?;
        Ok(Self {
            scenario,
            renderer,
            drivers,
            extras,
            state: Mutex::new(state),
        })
    }

    /// Starts the run again from its start with `seed` (default: this simulation's seed) and
    /// returns the first observation (a team's: a dict of observations by robot name); with
    /// `scenario`, runs that scenario from now on (another placement of the same robots:
    /// their names, cameras and actuators must be this one's, `ValueError` if not).
    #[pyo3(signature = (seed = None, scenario = None))]
    fn reset(
        &mut self,
        py: Python<'_>,
        seed: Option<u64>,
        scenario: Option<PyRef<'_, PyScenario>>,
    ) -> PyResult<Py<PyAny>> {
        if self.drivers.contains(&Driver::Ssl) {
            return Err(PyRuntimeError::new_err(
                "a Simulation served over the SSL protocol (robot=\"ssl\") holds its ports: it \
                 cannot be reset; make a new one (or teleport the robots and the ball over the \
                 control port)",
            ));
        }
        if let Some(s) = &scenario {
            same_shape(&self.scenario.scenario, &s.scenario).map_err(PyValueError::new_err)?;
        }
        let seed = seed.unwrap_or_else(|| self.lock().seed());
        let from = scenario.as_deref().unwrap_or(&self.scenario).clone();
        let fresh = py
            .detach(|| {
                State::new(
                    &from.scenario,
                    seed,
                    self.renderer,
                    &self.drivers,
                    None,
                    self.extras,
                )
            })
            .map_err(run_error)?;
        self.scenario = from;
        let mut state = self.lock();
        *state = fresh;
        observations(py, &state)
    }

    /// With `robot="ssl"`: where the protocol's ports are (`control`, `blue`, `yellow`, and
    /// where `vision` and `referee` go), as `"host:port"`; `None` otherwise.
    fn ssl_ports<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let state = self.lock();
        let Some(b) = state.ssl_ports() else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        for (k, v) in [
            ("control", b.control),
            ("blue", b.blue),
            ("yellow", b.yellow),
            ("vision", b.vision_to),
            ("referee", b.referee_to),
        ] {
            d.set_item(k, v.to_string())?;
        }
        Ok(Some(d))
    }

    /// The observation now (what the last `reset` or `step` returned).
    fn observe(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        observations(py, &self.lock())
    }

    /// One control cycle. The one robot driven by Python takes `command`: `(vx_mm_s,
    /// vy_mm_s, omega_rad_s)` in the body frame (x forward, y left; a differential robot takes
    /// `(v_mm_s, omega_rad_s)`), `actuators` an optional list of pan commands (`{"sensor":
    /// NAME, "pan_rad": A}` or `{"sensor": NAME, "rate_rad_s": W}`), and `estimate` an
    /// optional `(x_mm, y_mm, theta_rad)` recorded as the robot's own estimate; with
    /// `robot="builtin"` no command is given. A team takes each as a dict by robot name,
    /// holding every robot Python drives. Returns the next observation (a team's: a dict).
    /// Raises `RunFinishedError` once the run is over, `RobotSoftwareError` when the built-in
    /// software fails, `RenderError` when the renderer does.
    #[pyo3(signature = (command = None, actuators = None, estimate = None))]
    fn step(
        &self,
        py: Python<'_>,
        command: Option<&Bound<'_, PyAny>>,
        actuators: Option<&Bound<'_, PyAny>>,
        estimate: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Py<PyAny>> {
        let cmds = {
            let state = self.lock();
            if state.done() {
                return Err(RunFinishedError::new_err(format!(
                    "the run is over after {} cycles (time up or goal reached): call reset() \
                     to run again",
                    state.session().simulation().cycle()
                )));
            }
            match state.is_team() {
                true => self.team_commands(&state, command, actuators, estimate)?,
                false => self.one_command(&state, command, actuators, estimate)?,
            }
        };
        py.detach(|| self.lock().step_all(cmds))
            .map_err(run_error)?;
        observations(py, &self.lock())
    }

    /// Puts the ball at `(x_mm, y_mm)` on the floor, going at `(vx_mm_s, vy_mm_s)` (an
    /// experimenter placing or rolling it; a dribbler holding it lets go). Raises `ValueError`
    /// without a ball, off the floor or with a number not finite.
    #[pyo3(signature = (x_mm, y_mm, vx_mm_s = 0.0, vy_mm_s = 0.0))]
    fn place_ball(&self, x_mm: f64, y_mm: f64, vx_mm_s: f64, vy_mm_s: f64) -> PyResult<()> {
        let mut state = self.lock();
        let sim = state.session_mut().simulation_mut();
        sim.place_ball(Point2::new(x_mm, y_mm), Vector2::new(vx_mm_s, vy_mm_s))
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// The truth now (the simulator's side, never part of an observation): `t_s`, `x_mm`,
    /// `y_mm`, `theta_rad`, `vx_mm_s`, `vy_mm_s` (world frame), `omega_rad_s`, `contacts` so
    /// far, `reached_goal`, `targets_reached` (with waypoints), and with a ball `ball` (`x_mm`,
    /// `y_mm`, `z_mm`, `vx_mm_s`, `vy_mm_s`, `vz_mm_s`) and `ball_in_dribbler`; a team's: a dict
    /// of these by robot name.
    fn truth<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let state = self.lock();
        per_robot(py, &state, |k| {
            let t = state.truth_of(k).unwrap_or_else(|| state.truth());
            Ok(truth_dict(py, &t)?.into_any())
        })
    }

    /// The truth beside each frame `robot`'s software got in the last cycle (default: the
    /// first robot), by camera name (the simulator's side, never part of an observation):
    /// `depth_mm` (`float32` `H x W`: how far the light travelled to the camera, mirror
    /// included; inf for the sky, NaN where the pixel sees no mirror), `floor_mm` (`float32`:
    /// the floor point's distance from the robot's centre where the pixel shows the floor, NaN
    /// elsewhere), `labels` (`uint16`: what the pixel shows) and `legend` (the labels' entries
    /// as `legend.json` holds them). Raises `ValueError` unless made with `truth=True`.
    #[pyo3(signature = (robot = None))]
    fn truth_frames<'py>(
        &self,
        py: Python<'py>,
        robot: Option<&str>,
    ) -> PyResult<Bound<'py, PyDict>> {
        if !self.extras.truth {
            return Err(PyValueError::new_err(NO_TRUTH));
        }
        let state = self.lock();
        let k = state.robot_index(robot)?;
        truth_frames(py, &state, k)
    }

    /// The last cycle's `estimates.jsonl` record (truth beside belief) as a dict; `None`
    /// before the first step (a team's: a dict of these by robot name).
    fn record<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let state = self.lock();
        per_robot(py, &state, |k| {
            Ok(last_record(py, &state, k)?.unwrap_or_else(|| py.None().into_bound(py)))
        })
    }

    /// The run's `summary.json` so far, as a dict.
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let out = self.lock().session().output();
        let text = serde_json::to_string(&out.summary)
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        json_to_py(py, &text)
    }

    /// The trajectory so far: a dict of NumPy columns named as `trajectory.csv`'s header (a
    /// team's: a dict of these by robot name).
    fn trajectory<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let state = self.lock();
        let robots = state.session().simulation().robots();
        per_robot(py, &state, |k| {
            Ok(crate::convert::trajectory_columns(py, robots[k].trajectory())?.into_any())
        })
    }

    /// Writes what `omniloop run` writes for the run so far (`summary.json`,
    /// `trajectory.csv`, `estimates.jsonl`, `topview.png`, the experiment's files; a team's
    /// records under `robots/NAME/`) into `dir`.
    fn write(&self, py: Python<'_>, dir: PathBuf) -> PyResult<()> {
        let state = self.lock();
        let out = state.session().output_with_files().map_err(run_error)?;
        let scenario = state.session().simulation().scenario().clone();
        drop(state);
        py.detach(|| omniloop::report::write_run(&dir, &scenario, &out))
            .map_err(|e| PyOSError::new_err(format!("{e:#}")))
    }

    /// A top view of the moment (world, paths so far, start and goal; every robot of a team)
    /// as an `H x W x 3` `uint8` array `width` pixels wide.
    #[pyo3(signature = (width = 640))]
    fn topview<'py>(&self, py: Python<'py>, width: u32) -> PyResult<Bound<'py, PyAny>> {
        if !(200..=4000).contains(&width) {
            return Err(PyValueError::new_err(format!(
                "width={width}: a top view is 200 to 4000 pixels wide"
            )));
        }
        let state = self.lock();
        let sim = state.session().simulation();
        let out = sim.output(0.0);
        let img = omniloop::report::run_topview_image("topview", sim.scenario(), &out, width)
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        Ok(rgb_image_array(py, img).into_any())
    }

    /// The scenario being run.
    #[getter]
    fn scenario(&self) -> PyScenario {
        self.scenario.clone()
    }

    /// The seed of the run now.
    #[getter]
    fn seed(&self) -> u64 {
        self.lock().seed()
    }

    /// Control cycles run so far.
    #[getter]
    fn cycle(&self) -> u64 {
        self.lock().session().simulation().cycle()
    }

    /// Whether the run is over.
    #[getter]
    fn done(&self) -> bool {
        self.lock().done()
    }

    /// The free-space stage of `robot`'s vision camera (default: the first robot), built as
    /// the built-in robot builds it (its calibration, its `[vision.freespace]` settings), to
    /// run on frames from `observe()` or `step()`; raises `ValueError` when its vision camera
    /// is not a mirror that sees the floor.
    #[pyo3(signature = (robot = None))]
    fn free_space_detector(&self, robot: Option<&str>) -> PyResult<PyFreeSpaceDetector> {
        let state = self.lock();
        let k = state.robot_index(robot)?;
        let agent = &state.session().simulation().robots()[k];
        let name = agent.name().to_string();
        let Some(cal) = agent.vision_calibration() else {
            return Err(PyValueError::new_err(format!(
                "robot {name:?}: its vision camera is not a mirror camera with an image-to-floor \
                 calibration, so it has no free space"
            )));
        };
        let config: FreeSpaceConfig = agent
            .scenario()
            .vision
            .table("freespace")
            .map_err(|e| PyValueError::new_err(format!("robot {name:?}: {e}")))?;
        let stage = FreeSpaceStage::new(&cal.sensor, config, cal)
            .map_err(|e| PyValueError::new_err(format!("robot {name:?}: {e}")))?;
        Ok(PyFreeSpaceDetector::new(stage))
    }

    /// The robots' names, in the scenario's order (`["robot"]` for a one-robot scenario
    /// that names none).
    #[getter]
    fn robots(&self) -> Vec<String> {
        self.lock().names()
    }

    /// The robots Python drives, by name.
    #[getter]
    fn python_robots(&self) -> Vec<String> {
        let state = self.lock();
        self.driven_by_python(&state)
    }

    /// The cameras, in the scenario's order (a team's: a dict of these by robot name).
    #[getter]
    fn sensors<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let state = self.lock();
        per_robot(py, &state, |k| {
            Ok(PyList::new(py, state.members[k].sensors.clone())?.into_any())
        })
    }

    fn __repr__(&self) -> String {
        let state = self.lock();
        let robot = |d: &Driver| match d {
            Driver::Python => "python",
            Driver::Builtin => "builtin",
            Driver::Ssl => "ssl",
        };
        let drivers = match state.is_team() {
            true => format!(
                "{{{}}}",
                state
                    .names()
                    .iter()
                    .zip(&self.drivers)
                    .map(|(n, d)| format!("{n:?}: {:?}", robot(d)))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            false => format!("{:?}", robot(&self.drivers[0])),
        };
        format!(
            "Simulation({:?}, seed={}, cycle={}, robot={drivers})",
            self.scenario.scenario.name,
            state.seed(),
            state.session().simulation().cycle(),
        )
    }
}
