//! `omniloop.FreeSpaceDetector`: the built-in robot's free-space stage on frames handed in from
//! Python (the floor region's free distance in every direction, eqs. (5)-(7) of the corner
//! paper), for software outside omniloop's loop, such as the ROS 2 bridge's `scan`.
//!
//! It is the robot's side: it reads a frame and the robot's own calibration and settings,
//! never the truth.

use crate::convert::rgba_from_array;
use crate::errors::RobotSoftwareError;
use numpy::{PyArray1, PyReadonlyArray3};
use omniloop::robot::perception::FreeSpaceStage;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::{Mutex, PoisonError};

/// The free-space stage of one robot's vision camera, fed frame by frame.
#[pyclass(module = "omniloop", name = "FreeSpaceDetector")]
pub struct PyFreeSpaceDetector {
    stage: Mutex<FreeSpaceStage>,
    camera: String,
}

impl PyFreeSpaceDetector {
    pub fn new(stage: FreeSpaceStage) -> Self {
        let camera = stage.camera().to_string();
        Self {
            stage: Mutex::new(stage),
            camera,
        }
    }
}

#[pymethods]
impl PyFreeSpaceDetector {
    /// The free space of `frame` (`H x W x 3` `uint8`, a frame of `camera` taken now), as the
    /// built-in robot's stage gives it: a dict of `direction_rad` (each direction's centre
    /// angle in the robot frame), `free_mm` (distance from the sensor axis to the first
    /// obstacle cell, or to the template's edge where free throughout), `clear_mm` (surely
    /// free), `front_mm` (farthest the obstacle's face can be), NumPy arrays; `range_mm` and
    /// `inner_mm` (the template's outer and inner edges on the floor); `axis_mm` (the sensor
    /// axis in the robot frame, the origin of the distances). Raises `RobotSoftwareError` when
    /// the stage fails on the frame (one smaller than the camera's image).
    fn detect<'py>(
        &self,
        py: Python<'py>,
        frame: PyReadonlyArray3<'py, u8>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let img = rgba_from_array(&frame)?;
        let fs = py
            .detach(|| {
                self.stage
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner)
                    .detect_frame(&img)
            })
            .map_err(|e| RobotSoftwareError::new_err(format!("free space: {e}")))?;
        let d = PyDict::new(py);
        d.set_item("direction_rad", PyArray1::from_slice(py, &fs.direction_rad))?;
        d.set_item("free_mm", PyArray1::from_slice(py, &fs.free_mm))?;
        d.set_item("clear_mm", PyArray1::from_slice(py, &fs.clear_mm))?;
        d.set_item("front_mm", PyArray1::from_slice(py, &fs.front_mm))?;
        d.set_item("range_mm", fs.range_mm)?;
        d.set_item("inner_mm", fs.inner_mm)?;
        d.set_item("axis_mm", (fs.axis_mm.x, fs.axis_mm.y))?;
        Ok(d)
    }

    /// The camera whose frames it reads.
    #[getter]
    fn camera(&self) -> String {
        self.camera.clone()
    }

    fn __repr__(&self) -> String {
        format!("FreeSpaceDetector(camera={:?})", self.camera)
    }
}
