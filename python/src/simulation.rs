//! `omniloop.Simulation`: a run stepped from Python, with Python as the robot's software (or
//! the built-in stack), and the `Observation` it gives each step.
//!
//! The robot's side and the simulator's side stay apart: an `Observation` holds only what the
//! robot's own sensors give (frames, odometry with its errors, actuator state) and what it
//! works out from them (dead reckoning from the start it is told); the truth comes from
//! `Simulation.truth()`, for scoring and recording.

use crate::convert::{finite_numbers, json_to_py, rgb_array, rgb_image_array, run_error};
use crate::scenario::PyScenario;
use nalgebra::{Isometry2, Vector2};
use omniloop::control::DeadReckoning;
use omniloop::robot::{ActuatorCommand, ActuatorState, BodyCommand, Remote, RemoteHandle};
use omniloop::run::record::estimates_line;
use omniloop::run::{RunError, RunOptions};
use omniloop::scenario::PilotChoice;
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
}

impl Driver {
    pub fn parse(robot: &str) -> PyResult<Self> {
        match robot {
            "python" => Ok(Self::Python),
            "builtin" => Ok(Self::Builtin),
            other => Err(PyValueError::new_err(format!(
                "robot={other:?}: expected \"python\" (your commands) or \"builtin\" (the \
                 scenario's own robot software)"
            ))),
        }
    }
}

/// The renderer named in Python.
pub fn renderer_choice(name: &str) -> PyResult<RendererChoice> {
    name.parse()
        .map_err(|e: String| PyValueError::new_err(format!("renderer={name:?}: {e}")))
}

/// What Python hands one step: checked before the step runs.
#[derive(Debug, Clone, Default)]
pub struct Command {
    body: BodyCommand,
    actuators: Vec<ActuatorCommand>,
    estimate: Option<Isometry2<f64>>,
}

/// One run being stepped, with what the robot's side keeps between steps.
pub struct State {
    session: Session,
    remote: Option<RemoteHandle>,
    dead_reckoning: DeadReckoning,
    start: Isometry2<f64>,
    differential: bool,
    pan_sensors: Vec<String>,
    sensors: Vec<String>,
    seed: u64,
}

impl State {
    /// Builds the run of `scenario` with `seed` and senses its first frames.
    pub fn new(
        scenario: &Scenario,
        seed: u64,
        renderer: RendererChoice,
        driver: Driver,
        shared_gpu: Option<BatchHandle>,
    ) -> Result<Self, RunError> {
        let mut scenario = scenario.clone();
        scenario.seed = seed;
        if driver == Driver::Python {
            // Python is the robot's software: it drives, whatever pilot the file names.
            scenario.run.pilot = PilotChoice::Robot;
        }
        let options = RunOptions {
            renderer,
            shared_gpu,
            ..RunOptions::default()
        };
        let mut remote = None;
        let session = match driver {
            Driver::Python => Session::new(
                &scenario,
                &options,
                |config| {
                    let (software, handle) = Remote::new(config, "python");
                    remote = Some(handle);
                    Ok(Box::new(software))
                },
                |_| {},
            )?,
            Driver::Builtin => {
                Session::new(&scenario, &options, omniloop::run::builtin_software, |_| {})?
            }
        };
        let r = &scenario.robot;
        Ok(Self {
            session,
            remote,
            dead_reckoning: DeadReckoning::new(),
            start: scenario.start().isometry(),
            differential: r.differential.is_some(),
            pan_sensors: r
                .sensors
                .iter()
                .filter(|s| s.optics.pinhole().is_some())
                .map(|s| s.name.clone())
                .collect(),
            sensors: r.sensors.iter().map(|s| s.name.clone()).collect(),
            seed,
        })
    }

    /// One control cycle with `command` (the Python robot's) and the odometry it brings.
    pub fn step(&mut self, command: Option<Command>) -> Result<(), RunError> {
        if let (Some(remote), Some(c)) = (&self.remote, command) {
            let mut m = remote.lock();
            m.command = c.body;
            m.actuators = c.actuators;
            m.estimate = c.estimate;
        }
        self.session.step()?;
        if let Some(r) = self.session.simulation().last_odometry() {
            self.dead_reckoning
                .update(r.v_body_mm_s, r.omega_rad_s, r.dt_s);
        }
        Ok(())
    }

    /// Whether the run is over.
    pub fn done(&self) -> bool {
        self.session.finished()
    }

    /// The truth now.
    pub fn truth(&self) -> Truth {
        self.session.simulation().truth()
    }

    /// The session.
    pub fn session(&self) -> &Session {
        &self.session
    }

    /// The seed of this run.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Where dead reckoning puts the robot (world frame, from the start it is told).
    pub fn odometry_pose(&self) -> Isometry2<f64> {
        self.start * self.dead_reckoning.pose()
    }

    /// The Python robot's command, checked against this robot: `(vx_mm_s, vy_mm_s,
    /// omega_rad_s)`, or `(v_mm_s, omega_rad_s)` for a differential drive; pan commands for
    /// cameras on pan units; an estimate `(x_mm, y_mm, theta_rad)`.
    pub fn command(
        &self,
        command: &Bound<'_, PyAny>,
        actuators: Option<&Bound<'_, PyAny>>,
        estimate: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Command> {
        let body = if self.differential {
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
            Some(a) if !a.is_none() => self.actuator_commands(a)?,
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
    /// `{"sensor": NAME, "rate_rad_s": W}` (pan at W until told otherwise).
    fn actuator_commands(&self, list: &Bound<'_, PyAny>) -> PyResult<Vec<ActuatorCommand>> {
        let shape = "actuators must be a list of dicts {\"sensor\": NAME, \"pan_rad\": A} or \
                     {\"sensor\": NAME, \"rate_rad_s\": W}";
        let items: Vec<Bound<'_, PyDict>> =
            list.extract().map_err(|_| PyValueError::new_err(shape))?;
        let mut out = Vec::with_capacity(items.len());
        for item in items {
            let sensor: String = item
                .get_item("sensor")?
                .ok_or_else(|| PyValueError::new_err(shape))?
                .extract()
                .map_err(|_| PyValueError::new_err(shape))?;
            if !self.pan_sensors.contains(&sensor) {
                return Err(PyValueError::new_err(format!(
                    "actuators: no pan unit carries camera {sensor:?} (cameras: {:?}; only \
                     pinhole cameras are on pan units: {:?})",
                    self.sensors, self.pan_sensors
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

/// The observation of `state` now.
pub fn observation(py: Python<'_>, state: &State) -> PyResult<Observation> {
    let sim = state.session().simulation();
    let frames = PyDict::new(py);
    for f in sim.frames() {
        frames.set_item(f.sensor, rgb_array(py, f.image))?;
    }
    let odometry = match sim.last_odometry() {
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
    for a in sim.actuator_state() {
        let ActuatorState::Pan { sensor, pan_rad } = a;
        actuators.set_item(sensor, pan_rad)?;
    }
    let record = match state.remote {
        Some(_) => None,
        None => last_line(state),
    };
    let p = state.odometry_pose();
    Ok(Observation {
        t_s: sim.truth().t_s,
        cycle: sim.cycle(),
        frames: frames.unbind(),
        odometry: Py::new(py, odometry)?,
        odometry_pose: (p.translation.x, p.translation.y, p.rotation.angle()),
        actuators: actuators.unbind(),
        done: state.done(),
        record,
    })
}

/// The last cycle's `estimates.jsonl` line (truth included), if a cycle ran.
fn last_line(state: &State) -> Option<String> {
    let sim = state.session().simulation();
    let estimates = sim.estimates();
    let k = estimates.len().checked_sub(1)?;
    Some(estimates_line(&sim.trajectory()[k], &estimates[k]))
}

/// The last cycle's `estimates.jsonl` record as a dict (truth included), if a cycle ran.
fn last_record<'py>(py: Python<'py>, state: &State) -> PyResult<Option<Bound<'py, PyAny>>> {
    last_line(state)
        .map(|line| json_to_py(py, &line))
        .transpose()
}

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
    Ok(d)
}

/// A scenario run stepped from Python.
#[pyclass(module = "omniloop", name = "Simulation")]
pub struct PySimulation {
    scenario: PyScenario,
    renderer: RendererChoice,
    driver: Driver,
    state: Mutex<State>,
}

impl PySimulation {
    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

#[pymethods]
impl PySimulation {
    /// A run of `scenario` with `seed` (default: the scenario's), the `renderer` (`"cpu"`,
    /// `"gpu"` or `"auto"`) and `robot`: `"python"` (you step it with commands) or
    /// `"builtin"` (the scenario's own robot software decides).
    #[new]
    #[pyo3(signature = (scenario, seed = None, renderer = "cpu", robot = "python"))]
    fn new(
        py: Python<'_>,
        scenario: PyRef<'_, PyScenario>,
        seed: Option<u64>,
        renderer: &str,
        robot: &str,
    ) -> PyResult<Self> {
        let renderer = renderer_choice(renderer)?;
        let driver = Driver::parse(robot)?;
        let scenario = scenario.clone();
        let seed = seed.unwrap_or(scenario.scenario.seed);
        let state = py
            .detach(|| State::new(&scenario.scenario, seed, renderer, driver, None))
            .map_err(run_error)?;
        Ok(Self {
            scenario,
            renderer,
            driver,
            state: Mutex::new(state),
        })
    }

    /// Starts the run again from its start with `seed` (default: this simulation's seed) and
    /// returns the first observation.
    #[pyo3(signature = (seed = None))]
    fn reset(&self, py: Python<'_>, seed: Option<u64>) -> PyResult<Observation> {
        let seed = seed.unwrap_or_else(|| self.lock().seed());
        let fresh = py
            .detach(|| {
                State::new(
                    &self.scenario.scenario,
                    seed,
                    self.renderer,
                    self.driver,
                    None,
                )
            })
            .map_err(run_error)?;
        let mut state = self.lock();
        *state = fresh;
        observation(py, &state)
    }

    /// The observation now (what the last `reset` or `step` returned).
    fn observe(&self, py: Python<'_>) -> PyResult<Observation> {
        observation(py, &self.lock())
    }

    /// One control cycle. With `robot="python"`, `command` is `(vx_mm_s, vy_mm_s,
    /// omega_rad_s)` in the body frame (x forward, y left; a differential robot takes
    /// `(v_mm_s, omega_rad_s)`), `actuators` an optional list of pan commands
    /// (`{"sensor": NAME, "pan_rad": A}` or `{"sensor": NAME, "rate_rad_s": W}`), and
    /// `estimate` an optional `(x_mm, y_mm, theta_rad)` recorded as the robot's own estimate.
    /// With `robot="builtin"` no command is given. Returns the next observation.
    #[pyo3(signature = (command = None, actuators = None, estimate = None))]
    fn step(
        &self,
        py: Python<'_>,
        command: Option<&Bound<'_, PyAny>>,
        actuators: Option<&Bound<'_, PyAny>>,
        estimate: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Observation> {
        let cmd = {
            let state = self.lock();
            if state.done() {
                return Err(PyRuntimeError::new_err(format!(
                    "the run is over after {} cycles (time up or goal reached): call reset() \
                     to run again",
                    state.session().simulation().cycle()
                )));
            }
            match (self.driver, command) {
                (Driver::Python, Some(c)) if !c.is_none() => {
                    Some(state.command(c, actuators, estimate)?)
                }
                (Driver::Python, _) => {
                    return Err(PyValueError::new_err(
                        "step() needs a command: (vx_mm_s, vy_mm_s, omega_rad_s), or (v_mm_s, \
                         omega_rad_s) for a differential robot",
                    ));
                }
                (Driver::Builtin, Some(c)) if !c.is_none() => {
                    return Err(PyValueError::new_err(
                        "robot=\"builtin\" decides its own commands: call step() without one",
                    ));
                }
                (Driver::Builtin, _) => None,
            }
        };
        py.detach(|| self.lock().step(cmd)).map_err(run_error)?;
        observation(py, &self.lock())
    }

    /// The truth now (the simulator's side, never part of an observation): `t_s`, `x_mm`,
    /// `y_mm`, `theta_rad`, `vx_mm_s`, `vy_mm_s` (world frame), `omega_rad_s`, `contacts` so
    /// far, `reached_goal`, `targets_reached` (with waypoints).
    fn truth<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        truth_dict(py, &self.lock().truth())
    }

    /// The last cycle's `estimates.jsonl` record (truth beside belief) as a dict; `None`
    /// before the first step.
    fn record<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        last_record(py, &self.lock())
    }

    /// The run's `summary.json` so far, as a dict.
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let out = self.lock().session().output();
        let text = serde_json::to_string(&out.summary)
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        json_to_py(py, &text)
    }

    /// The trajectory so far: a dict of NumPy columns named as `trajectory.csv`'s header.
    fn trajectory<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let state = self.lock();
        crate::convert::trajectory_columns(py, state.session().simulation().trajectory())
    }

    /// Writes what `omniloop run` writes for the run so far (`summary.json`,
    /// `trajectory.csv`, `estimates.jsonl`, `topview.png`, the experiment's files) into `dir`.
    fn write(&self, py: Python<'_>, dir: PathBuf) -> PyResult<()> {
        let state = self.lock();
        let out = state.session().output_with_files().map_err(run_error)?;
        let scenario = state.session().simulation().scenario().clone();
        drop(state);
        py.detach(|| omniloop::report::write_run(&dir, &scenario, &out))
            .map_err(|e| PyOSError::new_err(format!("{e:#}")))
    }

    /// A top view of the moment (world, paths so far, start and goal) as an `H x W x 3`
    /// `uint8` array `width` pixels wide.
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

    /// The cameras, in the scenario's order.
    #[getter]
    fn sensors<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        PyList::new(py, self.lock().sensors.clone())
    }

    fn __repr__(&self) -> String {
        let state = self.lock();
        format!(
            "Simulation({:?}, seed={}, cycle={}, robot={:?})",
            self.scenario.scenario.name,
            state.seed(),
            state.session().simulation().cycle(),
            match self.driver {
                Driver::Python => "python",
                Driver::Builtin => "builtin",
            }
        )
    }
}
