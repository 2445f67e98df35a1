//! The `omniloop` Python package's native module (`omniloop._omniloop`): scenarios, whole runs,
//! a simulation stepped from Python with Python as the robot's software, and N of them stepped
//! together, the truth beside each frame and truth datasets. The pure-Python part (`omniloop/`)
//! adds the Gymnasium environments and the datasets' loader.

mod camera;
mod convert;
mod errors;
mod freespace;
mod scenario;
mod simulation;
mod ssl;
mod sweep;
mod truth;
mod vector;

use convert::{json_to_py, trajectory_columns};
use errors::run_error;
use pyo3::exceptions::{PyOSError, PyRuntimeError};
use pyo3::prelude::*;
use scenario::PyScenario;
use std::path::PathBuf;

/// What `omniloop.run` gives: the summary and the trajectory, and where the files went.
#[pyclass(module = "omniloop", name = "RunResult", frozen, get_all)]
struct RunResult {
    /// `summary.json` as a dict.
    summary: Py<PyAny>,
    /// `trajectory.csv` as a dict of NumPy columns named as its header (NaN where empty); a
    /// team's: a dict of these by robot name.
    trajectory: Py<PyAny>,
    /// The folder the run's files were written to, if any.
    out: Option<PathBuf>,
}

#[pymethods]
impl RunResult {
    fn __repr__(&self, py: Python<'_>) -> String {
        let s = self.summary.bind(py);
        let get = |k: &str| s.get_item(k).map(|v| v.to_string()).unwrap_or_default();
        format!(
            "RunResult(scenario={}, seed={}, cycles={}, reached_goal={}, wall_contacts={})",
            get("scenario"),
            get("seed"),
            get("cycles"),
            get("reached_goal"),
            get("wall_contacts")
        )
    }
}

/// Runs `scenario` with the built-in robot as `omniloop run` does (its experiment's
/// procedure, its metrics), with `seed` (default: the scenario's) on `renderer`; `out` also
/// writes the run's files there; `progress(cycle, total)` is called as the run goes (at most
/// a hundred times).
#[pyfunction]
#[pyo3(signature = (scenario, seed = None, renderer = "cpu", out = None, progress = None))]
fn run(
    py: Python<'_>,
    scenario: &PyScenario,
    seed: Option<u64>,
    renderer: &str,
    out: Option<PathBuf>,
    progress: Option<Py<PyAny>>,
) -> PyResult<RunResult> {
    let choice = simulation::renderer_choice(renderer)?;
    let mut s = scenario.scenario.clone();
    if let Some(seed) = seed {
        s.seed = seed;
    }
    let mut failed: Option<PyErr> = None;
    let mut shown = 0;
    let report = |cycle: u64, total: u64| {
        let Some(callback) = &progress else { return };
        let step = (cycle * 100) / total.max(1);
        if failed.is_some() || (step == shown && cycle != total) {
            return;
        }
        shown = step;
        Python::attach(|py| {
            if let Err(e) = callback.call1(py, (cycle, total)) {
                failed = Some(e);
            }
        });
    };
    let output = py
        .detach(|| {
            omniloop::Runner::new(&s)
                .renderer(choice)
                .progress(report)
                .run()
        })
        .map_err(run_error)?;
    if let Some(e) = failed {
        return Err(e);
    }
    if let Some(dir) = &out {
        py.detach(|| omniloop::report::write_run(dir, &s, &output))
            .map_err(|e| PyOSError::new_err(format!("{e:#}")))?;
    }
    let summary = serde_json::to_string(&output.summary)
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    let trajectory = if output.robots.is_empty() {
        trajectory_columns(py, &output.trajectory)?.into_any()
    } else {
        // A team's: the columns of each robot, by name.
        let d = pyo3::types::PyDict::new(py);
        for r in &output.robots {
            d.set_item(&r.name, trajectory_columns(py, &r.trajectory)?)?;
        }
        d.into_any()
    };
    Ok(RunResult {
        summary: json_to_py(py, &summary)?.unbind(),
        trajectory: trajectory.unbind(),
        out,
    })
}

/// The commented default scenario, every key with its default (`omniloop run --print-default`).
#[pyfunction]
fn default_scenario() -> &'static str {
    omniloop::DEFAULT_SCENARIO
}

#[pymodule]
fn _omniloop(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::add_exceptions(m)?;
    m.add_class::<PyScenario>()?;
    m.add_class::<RunResult>()?;
    m.add_class::<simulation::PySimulation>()?;
    m.add_class::<simulation::Observation>()?;
    m.add_class::<simulation::Odometry>()?;
    m.add_class::<vector::PyVectorSimulation>()?;
    m.add_class::<freespace::PyFreeSpaceDetector>()?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(default_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(truth::write_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(truth::read_png_levels, m)?)?;
    m.add_function(wrap_pyfunction!(truth::read_png_rgb, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::sweep_plan, m)?)?;
    m.add_class::<sweep::SweepPlan>()?;
    m.add_function(wrap_pyfunction!(sweep::run_planned_job, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
