//! The errors Python sees: `ScenarioError` (a `ValueError`) for a scenario that is not valid or
//! that a run cannot take, and the `SimulationError` family (`RuntimeError`s) for a run that
//! fails as it goes, mapped from the Rust errors in one place ([`run_error`]).

use omniloop::run::RunError;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    omniloop,
    ScenarioError,
    PyValueError,
    "A scenario file or text that is not a valid scenario: the message is the command line's \
     `FILE:LINE:COLUMN: field PATH: message`, a line a problem."
);

pyo3::create_exception!(
    omniloop,
    SimulationError,
    PyRuntimeError,
    "A run that failed as it went (a `RuntimeError`): the world could not be built, a \
     calibration could not be used, a frame or its truth could not be written, a team's robots \
     and their software do not match. Its subclasses say which part failed."
);

pyo3::create_exception!(
    omniloop,
    RobotSoftwareError,
    SimulationError,
    "The robot's software failed (a `SimulationError`): the built-in stack could not be built or \
     failed on a cycle (a vision stage on a frame, a controller), a robot commanded an actuator \
     it does not have, or one robot of a team failed (the message names it)."
);

pyo3::create_exception!(
    omniloop,
    RenderError,
    SimulationError,
    "The renderer could not open or render (a `SimulationError`): no GPU adapter for \
     `renderer=\"gpu\"`, a GPU device error, or a frame that cannot be made."
);

pyo3::create_exception!(
    omniloop,
    RunFinishedError,
    SimulationError,
    "A run that is over was stepped again (a `SimulationError`): time up or the goal reached; \
     `reset()` it to run again."
);

/// Adds the exceptions to the native module.
pub fn add_exceptions(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ScenarioError", py.get_type::<ScenarioError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add("RobotSoftwareError", py.get_type::<RobotSoftwareError>())?;
    m.add("RenderError", py.get_type::<RenderError>())?;
    m.add("RunFinishedError", py.get_type::<RunFinishedError>())?;
    Ok(())
}

/// A run that could not go on, as the Python exception a user catches: `ScenarioError` for a
/// scenario the run cannot take; `RobotSoftwareError` for the robot's software;
/// `RenderError` for the renderer; `RunFinishedError` for a run stepped after its end;
/// `SimulationError` for the rest. The one place the run's errors are matched.
pub fn run_error(e: RunError) -> PyErr {
    let message = e.to_string();
    match e {
        RunError::Scenario(m) => ScenarioError::new_err(m),
        RunError::Robot(_) | RunError::InRobot { .. } | RunError::Actuator(_) => {
            RobotSoftwareError::new_err(message)
        }
        RunError::Render(_) => RenderError::new_err(message),
        RunError::Finished { .. } => RunFinishedError::new_err(message),
        RunError::Sim(_)
        | RunError::Control(_)
        | RunError::Vision(_)
        | RunError::Team(_)
        | RunError::Truth(_)
        | RunError::Frame { .. } => SimulationError::new_err(message),
    }
}
