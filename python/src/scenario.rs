//! `omniloop.Scenario`: a validated scenario, loaded from a file or text, with values set by
//! the dotted keys of `omniloop sweep --set`.

use crate::convert::toml_value;
use crate::errors::ScenarioError;
use omniloop::scenario::LoadError;
use omniloop::{Scenario, load_scenario, parse_scenario};
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::{Path, PathBuf};

/// The file name messages give a scenario made from text.
const TEXT_FILE: &str = "<string>";

/// A scenario, checked as `omniloop check` checks it.
#[pyclass(module = "omniloop", name = "Scenario", frozen)]
#[derive(Clone)]
pub struct PyScenario {
    pub scenario: Scenario,
    /// Its TOML text (with any values set).
    text: String,
    /// The file it came from (`<string>` for text), named in messages.
    file: PathBuf,
}

fn load_error(e: LoadError) -> PyErr {
    match e {
        LoadError::Io { file, reason } if reason.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(format!("no scenario file {}", file.display()))
        }
        LoadError::Io { .. } => PyOSError::new_err(e.to_string()),
        LoadError::Invalid { .. } => ScenarioError::new_err(e.to_string()),
    }
}

impl PyScenario {
    /// Scenario text parsed and validated, its messages naming `file`.
    fn parsed(text: &str, file: PathBuf, name: &str) -> PyResult<Self> {
        let scenario = parse_scenario(text, &file, name).map_err(load_error)?;
        Ok(Self {
            scenario,
            text: text.to_string(),
            file,
        })
    }
}

#[pymethods]
impl PyScenario {
    /// Reads, parses and validates a scenario file; raises `ScenarioError` with every problem
    /// as `FILE:LINE:COLUMN: field PATH: message`.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        let scenario = load_scenario(&path).map_err(load_error)?;
        let text = std::fs::read_to_string(&path)
            .map_err(|e| PyOSError::new_err(format!("reading {}: {e}", path.display())))?;
        Ok(Self {
            scenario,
            text,
            file: path,
        })
    }

    /// Parses and validates scenario text (messages name it `<string>`); `name` is its name
    /// when the text gives none (default `scenario`).
    #[staticmethod]
    #[pyo3(signature = (text, name = "scenario"))]
    fn from_toml(text: &str, name: &str) -> PyResult<Self> {
        Self::parsed(text, PathBuf::from(TEXT_FILE), name)
    }

    /// A scenario file built into omniloop (`omniloop::BUNDLED_SCENARIOS`: `"blackout_stage1"`),
    /// its text as `scenarios/NAME.toml` holds it; raises `ValueError` naming the others.
    #[staticmethod]
    fn bundled(name: &str) -> PyResult<Self> {
        let Some((_, text)) = omniloop::BUNDLED_SCENARIOS.iter().find(|(n, _)| *n == name) else {
            let known: Vec<&str> = omniloop::BUNDLED_SCENARIOS
                .iter()
                .map(|(n, _)| *n)
                .collect();
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "no bundled scenario {name:?}: one of {}",
                known.join(", ")
            )));
        };
        Self::parsed(text, PathBuf::from(format!("scenarios/{name}.toml")), name)
    }

    /// A new scenario with each dotted key (`"robot.max_speed_mm_s"`,
    /// `"robot.sensors[0].noise_sigma"`, `"seed"`) set to its value, validated as
    /// `omniloop sweep --set` validates; raises `ScenarioError` naming the key.
    fn with_values(&self, values: &Bound<'_, PyDict>) -> PyResult<Self> {
        let mut pairs = Vec::with_capacity(values.len());
        for (k, v) in values.iter() {
            let key: String = k.extract().map_err(|_| {
                pyo3::exceptions::PyValueError::new_err("with_values: every key must be a str")
            })?;
            let value = toml_value(&key, &v)?;
            pairs.push((key, value));
        }
        let (mut scenario, text) = omniloop::sweep::with_values(&self.file, &self.text, &pairs)
            .map_err(|e| ScenarioError::new_err(e.join("\n")))?;
        if !pairs.iter().any(|(k, _)| k == "name") {
            scenario.name = self.scenario.name.clone();
        }
        Ok(Self {
            scenario,
            text,
            file: self.file.clone(),
        })
    }

    /// The scenario's TOML text (with the values set).
    fn to_toml(&self) -> String {
        self.text.clone()
    }

    /// Its name (the file stem unless it names itself).
    #[getter]
    fn name(&self) -> String {
        self.scenario.name.clone()
    }

    /// The file it came from (`None` for text).
    #[getter]
    fn path(&self) -> Option<PathBuf> {
        (self.file != Path::new(TEXT_FILE)).then(|| self.file.clone())
    }

    /// Its seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.scenario.seed
    }

    /// Longest simulated time, s (`run.duration_s`).
    #[getter]
    fn duration_s(&self) -> f64 {
        self.scenario.run.duration_s
    }

    /// One control cycle, s (`run.control_period_s`).
    #[getter]
    fn control_period_s(&self) -> f64 {
        self.scenario.run.control_period_s
    }

    /// Most control cycles a run lasts.
    #[getter]
    fn max_cycles(&self) -> u64 {
        self.scenario.max_cycles()
    }

    /// What the robot knows of itself: `name`, `start` (x_mm, y_mm, theta_rad), `radius_mm`,
    /// `max_speed_mm_s`, `accel_limit_mm_s2`, `angular_accel_limit_rad_s2`, `differential`
    /// (`None`, or `track_mm` and `max_turn_rate_rad_s`), `sensors` (name, width_px,
    /// height_px, kind, pan unit), and `goal` (`None`, or `x_mm`, `y_mm`, `tolerance_mm`,
    /// `waypoints_mm`); of a team, its first robot.
    #[getter]
    fn robot<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        robot_dict(
            py,
            &self.scenario.member(0),
            &self.scenario.robot_names()[0],
        )
    }

    /// Every robot as `robot` describes it, by name, in the scenario's order (one entry for
    /// a one-robot scenario).
    #[getter]
    fn robots<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (m, name) in self
            .scenario
            .members()
            .iter()
            .zip(self.scenario.robot_names())
        {
            d.set_item(&name, robot_dict(py, m, &name)?)?;
        }
        Ok(d)
    }

    /// Camera `sensor` of `robot` (defaults: the first of each) as a standard camera model,
    /// a dict: `image_size_px`, `intrinsics` (a pinhole camera's; for a mirror, Mei's unified
    /// model fitted to its traced rays, as `omniloop calibrate --format opencv-omnidir`
    /// writes it), `model_frame_in_body` (`rotation` whose columns are the model frame's axes
    /// in the body frame, `translation_mm`), `pan_unit`.
    #[pyo3(signature = (sensor = None, robot = None))]
    fn camera_model<'py>(
        &self,
        py: Python<'py>,
        sensor: Option<&str>,
        robot: Option<&str>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let names = self.scenario.robot_names();
        let k = match robot {
            None => 0,
            Some(r) => names.iter().position(|n| n == r).ok_or_else(|| {
                PyValueError::new_err(format!("no robot {r:?} (robots: {})", names.join(", ")))
            })?,
        };
        let member = self.scenario.member(k);
        let spec = member
            .sensor(sensor)
            .map_err(|e| PyValueError::new_err(format!("robot {:?}: {e}", names[k])))?;
        crate::camera::camera_model(py, spec)
    }

    /// Whether the scenario has a team (`[[robots]]`).
    #[getter]
    fn is_team(&self) -> bool {
        self.scenario.is_team()
    }

    fn __repr__(&self) -> String {
        format!(
            "Scenario({:?}, seed={})",
            self.scenario.name, self.scenario.seed
        )
    }
}

/// What robot `name` of a one-robot scenario `s` knows of itself (see `Scenario.robot`).
fn robot_dict<'py>(py: Python<'py>, s: &Scenario, name: &str) -> PyResult<Bound<'py, PyDict>> {
    let r = &s.robot;
    let d = PyDict::new(py);
    d.set_item("name", name)?;
    let start = s.start();
    d.set_item(
        "start",
        (start.x_mm, start.y_mm, start.heading_deg.to_radians()),
    )?;
    d.set_item("radius_mm", r.radius_mm)?;
    d.set_item("max_speed_mm_s", r.max_speed_mm_s)?;
    d.set_item("accel_limit_mm_s2", r.accel_limit_mm_s2)?;
    d.set_item("angular_accel_limit_rad_s2", r.angular_accel_limit_rad_s2)?;
    match &r.kicker {
        Some(k) => {
            let kd = PyDict::new(py);
            kd.set_item("max_kick_mm_s", k.max_kick_mm_s)?;
            kd.set_item("full_pull_rpm", k.full_pull_rpm)?;
            kd.set_item("front_mm", k.front_mm)?;
            d.set_item("kicker", kd)?;
        }
        None => d.set_item("kicker", py.None())?,
    }
    match &r.differential {
        Some(diff) => {
            let dd = PyDict::new(py);
            dd.set_item("track_mm", diff.track_mm)?;
            dd.set_item("max_turn_rate_rad_s", diff.max_turn_rate_deg_s.to_radians())?;
            d.set_item("differential", dd)?;
        }
        None => d.set_item("differential", py.None())?,
    }
    let sensors = PyList::empty(py);
    for spec in &r.sensors {
        let sd = PyDict::new(py);
        sd.set_item("name", &spec.name)?;
        sd.set_item("width_px", spec.width_px)?;
        sd.set_item("height_px", spec.height_px)?;
        sd.set_item("kind", spec.optics.kind())?;
        sd.set_item("pan_unit", spec.optics.pinhole().is_some())?;
        sensors.append(sd)?;
    }
    d.set_item("sensors", sensors)?;
    let o = &s.odometry;
    let od = PyDict::new(py);
    od.set_item("speed_noise_frac", o.speed_noise_frac)?;
    od.set_item("omega_noise_rad_s", o.omega_noise_rad_s)?;
    od.set_item("scale_bias_frac", o.scale_bias_frac)?;
    od.set_item("omega_bias_rad_s", o.omega_bias_rad_s)?;
    od.set_item("slip_s", o.slip_s)?;
    d.set_item("odometry", od)?;
    match &s.goal {
        Some(g) => {
            let gd = PyDict::new(py);
            gd.set_item("x_mm", g.x_mm)?;
            gd.set_item("y_mm", g.y_mm)?;
            gd.set_item("tolerance_mm", g.tolerance_mm)?;
            gd.set_item("waypoints_mm", g.waypoints_mm.clone())?;
            d.set_item("goal", gd)?;
        }
        None => d.set_item("goal", py.None())?,
    }
    Ok(d)
}
