//! Between Rust and Python: errors, images as NumPy arrays, JSON records as dicts, Python
//! values as TOML values, and the checks on what Python hands in.

use numpy::ndarray::Array3;
use numpy::{PyArray1, PyArray3, PyReadonlyArray3, PyUntypedArrayMethods};
use omniloop::TrajectoryRow;
use omniloop::vision::pixels;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// An RGBA image as an `H x W x 3` `uint8` array (the alpha channel, always opaque, dropped).
pub fn rgb_array<'py>(py: Python<'py>, img: &image::RgbaImage) -> Bound<'py, PyArray3<u8>> {
    let (w, h) = (img.width() as usize, img.height() as usize);
    rgb_from_vec(py, h, w, pixels::rgb_bytes(img))
}

/// An `H x W x 3` `uint8` array (an observation's frame) as an opaque RGBA image.
pub fn rgba_from_array(frame: &PyReadonlyArray3<'_, u8>) -> PyResult<image::RgbaImage> {
    let shape = frame.shape();
    if shape[2] != 3 || shape[0] == 0 || shape[1] == 0 {
        return Err(PyValueError::new_err(format!(
            "a frame is an H x W x 3 uint8 array (RGB), got shape {shape:?}"
        )));
    }
    let (h, w) = (shape[0], shape[1]);
    let view = frame.as_array();
    let standard = view.as_standard_layout();
    let rgb = standard.as_slice().unwrap_or(&[]);
    let size = u32::try_from(w).ok().zip(u32::try_from(h).ok());
    size.and_then(|(w, h)| pixels::rgba_from_rgb(w, h, rgb))
        .ok_or_else(|| {
            PyValueError::new_err(format!(
                "the frame's pixels do not fill its shape {shape:?}"
            ))
        })
}

/// An RGB image as an `H x W x 3` `uint8` array.
pub fn rgb_image_array<'py>(py: Python<'py>, img: image::RgbImage) -> Bound<'py, PyArray3<u8>> {
    let (w, h) = (img.width() as usize, img.height() as usize);
    rgb_from_vec(py, h, w, img.into_raw())
}

fn rgb_from_vec<'py>(
    py: Python<'py>,
    h: usize,
    w: usize,
    rgb: Vec<u8>,
) -> Bound<'py, PyArray3<u8>> {
    // The length is h * w * 3 by construction.
    let array = Array3::from_shape_vec((h, w, 3), rgb).unwrap_or_else(|_| Array3::zeros((h, w, 3)));
    PyArray3::from_owned_array(py, array)
}

/// A JSON text as Python objects (`json.loads`).
pub fn json_to_py<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

/// The trajectory as a dict of `float64` columns named as `trajectory.csv`'s header (an
/// estimate column is NaN where the robot had no estimate).
pub fn trajectory_columns<'py>(
    py: Python<'py>,
    rows: &[TrajectoryRow],
) -> PyResult<Bound<'py, PyDict>> {
    type Column = fn(&TrajectoryRow) -> f64;
    let columns: [(&str, Column); 11] = [
        ("t_s", |r| r.t_s),
        ("x_mm", |r| r.x_mm),
        ("y_mm", |r| r.y_mm),
        ("theta_rad", |r| r.theta_rad),
        ("vx_mm_s", |r| r.vx_mm_s),
        ("vy_mm_s", |r| r.vy_mm_s),
        ("cmd_vx_mm_s", |r| r.cmd_vx_mm_s),
        ("cmd_vy_mm_s", |r| r.cmd_vy_mm_s),
        ("est_x_mm", |r| r.est_x_mm.unwrap_or(f64::NAN)),
        ("est_y_mm", |r| r.est_y_mm.unwrap_or(f64::NAN)),
        ("est_theta_rad", |r| r.est_theta_rad.unwrap_or(f64::NAN)),
    ];
    let out = PyDict::new(py);
    for (name, get) in columns {
        let values: Vec<f64> = rows.iter().map(get).collect();
        out.set_item(name, PyArray1::from_vec(py, values))?;
    }
    Ok(out)
}

/// A Python value as a TOML value (`bool`, `int`, `float`, `str`, lists and tuples of them,
/// dicts with string keys); `key` names it in the error.
pub fn toml_value(key: &str, v: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    use toml::Value;
    if v.is_instance_of::<PyBool>() {
        return Ok(Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        let i: i64 = v.extract().map_err(|_| {
            PyValueError::new_err(format!(
                "value of `{key}`: {v} does not fit a 64-bit integer"
            ))
        })?;
        return Ok(Value::Integer(i));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(Value::String(v.extract()?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items = v.try_iter()?;
        let mut out = Vec::new();
        for item in items {
            out.push(toml_value(key, &item?)?);
        }
        return Ok(Value::Array(out));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, item) in d.iter() {
            let k: String = k.extract().map_err(|_| {
                PyValueError::new_err(format!("value of `{key}`: a table's keys must be strings"))
            })?;
            let value = toml_value(&format!("{key}.{k}"), &item)?;
            table.insert(k, value);
        }
        return Ok(Value::Table(table));
    }
    // NumPy's scalars: integers have `__index__`, floats `__float__`.
    if v.hasattr("__index__")?
        && let Ok(i) = v.extract::<i64>()
    {
        return Ok(Value::Integer(i));
    }
    if let Ok(x) = v.extract::<f64>() {
        return Ok(Value::Float(x));
    }
    Err(PyValueError::new_err(format!(
        "value of `{key}`: a {} cannot be written in a scenario (expected bool, int, float, str, \
         a list or a dict of them)",
        v.get_type().name()?
    )))
}

/// `n` finite numbers from a sequence (`what` names it in errors: "command").
pub fn finite_numbers(what: &str, v: &Bound<'_, PyAny>, expected: &str) -> PyResult<Vec<f64>> {
    let wrong = || {
        PyValueError::new_err(format!(
            "{what} must be a sequence of numbers ({expected}), got {}",
            v.repr().map(|r| r.to_string()).unwrap_or_default()
        ))
    };
    if v.is_instance_of::<PyString>() {
        return Err(wrong());
    }
    let values: Vec<f64> = v.extract().map_err(|_| wrong())?;
    if let Some((k, x)) = values.iter().enumerate().find(|(_, x)| !x.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "{what}[{k}] is {x}: every number must be finite ({expected})"
        )));
    }
    Ok(values)
}

/// The renderer named in Python.
pub fn renderer_choice(name: &str) -> PyResult<omniloop_sim::RendererChoice> {
    name.parse::<omniloop_sim::RendererChoice>()
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(format!("renderer={name:?}: {e}")))
}
