//! The truth beside each frame as NumPy arrays (`Simulation.truth_frames()`), and the truth
//! dataset from Python: `write_dataset` makes one as `omniloop dataset` does, `read_png_levels`
//! and `read_png_rgb` read its PNGs back for `omniloop.dataset.load`.
//!
//! All of it is the simulator's side: none of it reaches the robot's software.

use crate::convert::{json_to_py, renderer_choice, rgb_image_array};
use crate::errors::{ScenarioError, run_error};
use crate::scenario::PyScenario;
use numpy::ndarray::Array2;
use numpy::{PyArray2, PyArray3};
use omniloop::dataset::{DatasetError, DatasetOptions, PoseMode};
use omniloop::run::truth_files::{TruthFileError, read_levels};
use omniloop_sim::labels::Legend;
use omniloop_sim::render::TruthFrame;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

/// A row-major image of `height x width` values as an `H x W` array.
fn image_array<'py, T: numpy::Element + Clone>(
    py: Python<'py>,
    height: u32,
    width: u32,
    values: &[T],
) -> PyResult<Bound<'py, PyArray2<T>>> {
    let array = Array2::from_shape_vec((height as usize, width as usize), values.to_vec())
        .map_err(|e| PyRuntimeError::new_err(format!("a {width}x{height} image: {e}")))?;
    Ok(PyArray2::from_owned_array(py, array))
}

/// A legend as `legend.json` holds it: a list of dicts `{label, class, instance, name, rgb}`.
pub fn legend_list<'py>(py: Python<'py>, legend: &Legend) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(&legend.entries())
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    json_to_py(py, &text)
}

/// One frame's truth as a dict: `depth_mm` and `floor_mm` (`float32`), `labels` (`uint16`),
/// each `H x W`, and `legend`.
pub fn truth_frame_dict<'py>(py: Python<'py>, t: &TruthFrame) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("depth_mm", image_array(py, t.height, t.width, &t.depth_mm)?)?;
    d.set_item("floor_mm", image_array(py, t.height, t.width, &t.floor_mm)?)?;
    d.set_item("labels", image_array(py, t.height, t.width, &t.labels)?)?;
    d.set_item("legend", legend_list(py, &t.legend)?)?;
    Ok(d)
}

/// An `OSError` for `path` (a `FileNotFoundError` where it is missing), naming the file.
fn os_error(path: &Path, source: &std::io::Error) -> PyErr {
    let file = path.display().to_string();
    match source.raw_os_error() {
        // OSError(errno, strerror, filename) picks its subclass by errno.
        Some(errno) => PyOSError::new_err((errno, source.to_string(), file)),
        None => PyOSError::new_err(format!("{file}: {source}")),
    }
}

/// Reads a depth or label PNG as it is stored: an `H x W` `uint16` array of its grey levels or
/// palette indices (label numbers, not colours). Raises `OSError` when the file cannot be
/// read, `ValueError` when it is not such a PNG.
#[pyfunction]
pub fn read_png_levels(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyArray2<u16>>> {
    let levels = py.detach(|| read_levels(&path)).map_err(|e| match e {
        TruthFileError::Io { path, reason } => os_error(&path, &reason),
        png @ TruthFileError::Png { .. } => PyValueError::new_err(png.to_string()),
    })?;
    image_array(py, levels.height, levels.width, &levels.values)
}

/// Reads an image file as an `H x W x 3` `uint8` RGB array. Raises `OSError` when the file
/// cannot be read, `ValueError` when it is not an image.
#[pyfunction]
pub fn read_png_rgb(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyArray3<u8>>> {
    let image = py.detach(|| image::open(&path)).map_err(|e| match e {
        image::ImageError::IoError(source) => os_error(&path, &source),
        other => PyValueError::new_err(format!("{}: {other}", path.display())),
    })?;
    Ok(rgb_image_array(py, image.to_rgb8()))
}

/// A dataset that could not be made, as Python's errors: `ScenarioError` for a scenario that
/// cannot give one, `OSError` for a file, the run's (see [`run_error`]) for the run along
/// which it is taken, `RuntimeError` otherwise.
fn dataset_error(e: DatasetError) -> PyErr {
    match e {
        DatasetError::Scenario { .. } | DatasetError::Sensor { .. } => {
            ScenarioError::new_err(e.to_string())
        }
        DatasetError::Run(run) => run_error(run),
        DatasetError::Io { path, reason } => os_error(&path, &reason),
        DatasetError::Image { path, reason } => match reason {
            image::ImageError::IoError(io) => os_error(&path, &io),
            other => PyRuntimeError::new_err(format!("{}: {other}", path.display())),
        },
        DatasetError::Export(_) => PyRuntimeError::new_err(e.to_string()),
    }
}

/// Writes `samples` frames of `scenario`'s camera (`sensor`, default: the one vision uses,
/// else the robot's first) with their truth into the folder `out`, as `omniloop dataset`
/// does: poses `"random"` (over the floor, clear of everything) or `"along-run"` (the
/// scenario's own run), with `seed` (default: the scenario's) on `renderer`. Returns
/// `dataset.json`'s content as a dict.
#[pyfunction]
#[pyo3(signature = (
    scenario, out, samples = 100, poses = "random", sensor = None, renderer = "cpu", seed = None
))]
#[allow(clippy::too_many_arguments)] // Python's keywords, as `omniloop dataset` takes them.
pub fn write_dataset<'py>(
    py: Python<'py>,
    scenario: &PyScenario,
    out: PathBuf,
    samples: usize,
    poses: &str,
    sensor: Option<String>,
    renderer: &str,
    seed: Option<u64>,
) -> PyResult<Bound<'py, PyAny>> {
    if samples == 0 {
        return Err(PyValueError::new_err(
            "samples=0: a dataset holds at least one frame",
        ));
    }
    let poses: PoseMode = poses
        .parse::<PoseMode>()
        .map_err(|e| PyValueError::new_err(format!("poses={poses:?}: {e}")))?;
    let options = DatasetOptions {
        samples,
        poses,
        sensor,
        renderer: renderer_choice(renderer)?,
    };
    let mut s = scenario.scenario.clone();
    if let Some(seed) = seed {
        s.seed = seed;
    }
    let info = py
        .detach(|| omniloop::dataset::write_dataset(&s, &options, &out, |_, _| {}))
        .map_err(dataset_error)?;
    let text = serde_json::to_string(&info).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    json_to_py(py, &text)
}
