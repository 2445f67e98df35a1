//! `omniloop.VectorSimulation`: N runs of one scenario stepped together, in parallel on the
//! cores (and in shared GPU batches when the renderer is a GPU, as sweeps do). The Gymnasium
//! vector environment (`omniloop.gym.make_vec`) is built on it.

use crate::errors::{RenderError, RunFinishedError, run_error};
use crate::scenario::PyScenario;
use crate::simulation::{
    Command, Driver, Extras, NO_TRUTH, Observation, State, observation, renderer_choice,
    same_shape, truth_dict, truth_frames,
};
use omniloop_sim::RendererChoice;
use omniloop_sim::render::{BatchHandle, BatchServer};
use pyo3::exceptions::{PyIndexError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;
use std::sync::{Mutex, MutexGuard, PoisonError};

/// N runs of one scenario, stepped together.
#[pyclass(module = "omniloop", name = "VectorSimulation")]
pub struct PyVectorSimulation {
    scenario: PyScenario,
    renderer: RendererChoice,
    driver: Driver,
    /// The truth is traced beside each frame.
    truth: bool,
    states: Mutex<Vec<State>>,
    /// The GPU the runs' frames are traced on in batches (kept alive while they run).
    _gpu: Mutex<Option<BatchServer>>,
    gpu: Option<BatchHandle>,
}

impl PyVectorSimulation {
    fn lock(&self) -> MutexGuard<'_, Vec<State>> {
        self.states.lock().unwrap_or_else(PoisonError::into_inner)
    }

    fn build(&self, seed: u64) -> Result<State, omniloop::run::RunError> {
        self.build_from(&self.scenario.scenario, seed)
    }

    fn build_from(
        &self,
        scenario: &omniloop::scenario::Scenario,
        seed: u64,
    ) -> Result<State, omniloop::run::RunError> {
        State::new(
            scenario,
            seed,
            self.renderer,
            &[self.driver],
            self.gpu.clone(),
            Extras {
                frames: false,
                truth: self.truth,
            },
        )
    }
}

#[pymethods]
impl PyVectorSimulation {
    /// `num_envs` runs of `scenario`, run `i` with seed `seed + i` (default: the scenario's
    /// seed), on `renderer`, with `robot` `"python"` or `"builtin"`; `truth=True` traces the
    /// truth beside each frame (see `Simulation`).
    #[new]
    #[pyo3(signature = (
        scenario, num_envs, seed = None, renderer = "cpu", robot = "python", truth = false
    ))]
    fn new(
        py: Python<'_>,
        scenario: PyRef<'_, PyScenario>,
        num_envs: usize,
        seed: Option<u64>,
        renderer: &str,
        robot: &str,
        truth: bool,
    ) -> PyResult<Self> {
        if !(1..=4096).contains(&num_envs) {
            return Err(PyValueError::new_err(format!(
                "num_envs={num_envs}: from 1 to 4096 runs"
            )));
        }
        if scenario.scenario.is_team() {
            return Err(PyValueError::new_err(format!(
                "scenario {:?} has a team ([[robots]]): VectorSimulation steps one-robot \
                 scenarios; step a team with Simulation or omniloop.pettingzoo",
                scenario.scenario.name
            )));
        }
        let choice = renderer_choice(renderer)?;
        let driver = Driver::parse(robot)?;
        let server = omniloop::sweep::shared_gpu(choice)
            .map_err(|e| RenderError::new_err(format!("renderer={renderer:?}: {e}")))?;
        let gpu = server.as_ref().map(BatchServer::handle);
        let scenario = scenario.clone();
        let base = seed.unwrap_or(scenario.scenario.seed);
        let mut me = Self {
            scenario,
            renderer: choice,
            driver,
            truth,
            states: Mutex::new(Vec::new()),
            _gpu: Mutex::new(server),
            gpu,
        };
        let states = py
            .detach(|| {
                (0..num_envs as u64)
                    .into_par_iter()
                    .map(|i| me.build(base.wrapping_add(i)))
                    .collect::<Result<Vec<_>, _>>()
            })
            .map_err(run_error)?;
        me.states = Mutex::new(states);
        Ok(me)
    }

    /// How many runs.
    fn __len__(&self) -> usize {
        self.lock().len()
    }

    /// Starts run `index` again with `seed` (default: its seed) and returns its first
    /// observation; with `scenario`, from that scenario instead (another placement of the
    /// same robot: its robots, cameras and actuators must be this one's, `ValueError` if not).
    #[pyo3(signature = (index, seed = None, scenario = None))]
    fn reset(
        &self,
        py: Python<'_>,
        index: usize,
        seed: Option<u64>,
        scenario: Option<PyRef<'_, PyScenario>>,
    ) -> PyResult<Observation> {
        let old_seed = {
            let states = self.lock();
            let s = states
                .get(index)
                .ok_or_else(|| PyIndexError::new_err(format!("run {index} of {}", states.len())))?;
            s.seed()
        };
        let base = &self.scenario.scenario;
        let from = match &scenario {
            Some(s) => {
                same_shape(base, &s.scenario).map_err(PyValueError::new_err)?;
                &s.scenario
            }
            None => base,
        };
        let fresh = py
            .detach(|| self.build_from(from, seed.unwrap_or(old_seed)))
            .map_err(run_error)?;
        let mut states = self.lock();
        states[index] = fresh;
        observation(py, &states[index])
    }

    /// Every run's observation now.
    fn observe(&self, py: Python<'_>) -> PyResult<Vec<Observation>> {
        self.lock().iter().map(|s| observation(py, s)).collect()
    }

    /// One control cycle of every run whose `active` flag is true (default: all), in
    /// parallel: `commands` holds a command a run (a sequence or an `N x 3` / `N x 2` array;
    /// `None` with `robot="builtin"`); `actuators` optionally an entry a run, `None` or a list
    /// as `Simulation.step` takes it (pan commands; with a kicker, `{"kick_mm_s": S,
    /// "angle_rad": A}` and `{"dribbler_rpm": R}`). A finished run that is active raises
    /// `RunFinishedError`; a command a run cannot take, `ValueError`, before any run steps.
    /// Returns every run's observation.
    #[pyo3(signature = (commands = None, active = None, actuators = None))]
    fn step(
        &self,
        py: Python<'_>,
        commands: Option<&Bound<'_, PyAny>>,
        active: Option<Vec<bool>>,
        actuators: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Vec<Observation>> {
        let cmds = self.commands(commands, active, actuators)?;
        let result = py.detach(|| {
            let mut states = self.lock();
            states
                .par_iter_mut()
                .zip(cmds)
                .map(|(s, c)| match c {
                    Some(c) => s.step(c),
                    None => Ok(()),
                })
                .collect::<Result<Vec<()>, _>>()
        });
        result.map_err(run_error)?;
        self.observe(py)
    }

    /// Every run's truth now (see `Simulation.truth`).
    fn truth<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let dicts = self
            .lock()
            .iter()
            .map(|s| truth_dict(py, &s.truth()))
            .collect::<PyResult<Vec<Bound<'py, PyDict>>>>()?;
        PyList::new(py, dicts)
    }

    /// Every run's truth beside the frames its software got in the last cycle (see
    /// `Simulation.truth_frames`); raises `ValueError` unless made with `truth=True`.
    fn truth_frames<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        if !self.truth {
            return Err(PyValueError::new_err(NO_TRUTH));
        }
        let states = self.lock();
        states.iter().map(|s| truth_frames(py, s, 0)).collect()
    }

    /// Each run's seed.
    #[getter]
    fn seeds(&self) -> Vec<u64> {
        self.lock().iter().map(State::seed).collect()
    }

    /// Whether each run is over.
    #[getter]
    fn done(&self) -> Vec<bool> {
        self.lock().iter().map(State::done).collect()
    }

    /// The scenario being run.
    #[getter]
    fn scenario(&self) -> PyScenario {
        self.scenario.clone()
    }
}

/// `what`, one entry a run of `n` (`None` when not given).
fn per_run<'py>(
    what: &str,
    v: Option<&Bound<'py, PyAny>>,
    n: usize,
) -> PyResult<Option<Vec<Bound<'py, PyAny>>>> {
    let Some(v) = v.filter(|v| !v.is_none()) else {
        return Ok(None);
    };
    let rows: Vec<Bound<'py, PyAny>> = v.try_iter()?.collect::<PyResult<_>>()?;
    if rows.len() != n {
        return Err(PyValueError::new_err(format!(
            "{} {what} for {n} runs: one a run",
            rows.len()
        )));
    }
    Ok(Some(rows))
}

impl PyVectorSimulation {
    /// Each run's checked command (with its actuators' commands): `None` for a run left as it
    /// is; `Some(None)` for the built-in robot's step.
    fn commands(
        &self,
        commands: Option<&Bound<'_, PyAny>>,
        active: Option<Vec<bool>>,
        actuators: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Vec<Option<Option<Command>>>> {
        let states = self.lock();
        let n = states.len();
        let active = active.unwrap_or_else(|| vec![true; n]);
        if active.len() != n {
            return Err(PyValueError::new_err(format!(
                "active has {} flags for {n} runs",
                active.len()
            )));
        }
        let given = |v: Option<&Bound<'_, PyAny>>| v.is_some_and(|v| !v.is_none());
        if self.driver == Driver::Builtin && (given(commands) || given(actuators)) {
            return Err(PyValueError::new_err(
                "robot=\"builtin\" decides its own commands: call step() without any",
            ));
        }
        let rows = per_run("commands", commands, n)?;
        if self.driver == Driver::Python && rows.is_none() {
            return Err(PyValueError::new_err("step() needs a command a run"));
        }
        let acts = per_run("actuators", actuators, n)?;
        let mut out = Vec::with_capacity(n);
        for (i, (state, on)) in states.iter().zip(active).enumerate() {
            if !on {
                out.push(None);
                continue;
            }
            if state.done() {
                return Err(RunFinishedError::new_err(format!(
                    "run {i} is over: reset it (or leave it inactive) before stepping again"
                )));
            }
            let cmd = match &rows {
                Some(rows) => Some(
                    state
                        .command(&rows[i], acts.as_ref().map(|a| &a[i]), None)
                        .map_err(|e| PyValueError::new_err(format!("run {i}: {e}")))?,
                ),
                None => None,
            };
            out.push(Some(cmd));
        }
        Ok(out)
    }
}
