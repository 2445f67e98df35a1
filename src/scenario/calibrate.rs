//! Calibrating a mirror sensor: its traced image-to-floor map as the `vision` crate's
//! [`RadialCalibration`], with the paper's closed form fitted for hyperbolic mirrors.

use omniloop_sim::calibration::trace_radial_map;
use omniloop_sim::optics::Optics;
use omniloop_sim::{SensorSpec, SimError};
use omniloop_vision::RadialCalibration;
use omniloop_vision::calibration::fit_hyperbolic_form;
use std::sync::Mutex;

/// Sample spacing of calibration tables, px.
pub const CALIBRATION_STEP_PX: f64 = 0.25;

/// Calibrations traced so far in this process, by sensor: validating a scenario and running
/// it need the same table, which is traced once.
static TRACED: Mutex<Vec<(SensorSpec, RadialCalibration)>> = Mutex::new(Vec::new());

/// Traces the radial map of `spec` and, for a hyperbolic mirror, fits
/// `f(R) = R / (A - B sqrt(C + R^2))` to the samples below 95% of the horizon radius. A sensor
/// traced before in this process is not traced again.
pub fn calibrate_sensor(spec: &SensorSpec) -> Result<RadialCalibration, SimError> {
    let traced = |t: &Vec<(SensorSpec, RadialCalibration)>| {
        t.iter().find(|(s, _)| s == spec).map(|(_, c)| c.clone())
    };
    if let Some(c) = traced(&TRACED.lock().unwrap_or_else(|e| e.into_inner())) {
        return Ok(c);
    }
    let cal = trace(spec)?;
    TRACED
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push((spec.clone(), cal.clone()));
    Ok(cal)
}

fn trace(spec: &SensorSpec) -> Result<RadialCalibration, SimError> {
    let sensor = spec.build();
    let map = trace_radial_map(&sensor, CALIBRATION_STEP_PX)?;
    let fit = match sensor.optics {
        Optics::Hyperbolic(_) => {
            let limit = 0.95 * map.horizon_px;
            let pts: Vec<[f64; 2]> = map
                .samples
                .iter()
                .copied()
                .filter(|s| s[0] <= limit)
                .collect();
            fit_hyperbolic_form(&pts)
        }
        _ => None,
    };
    Ok(RadialCalibration {
        sensor: sensor.name.clone(),
        width_px: sensor.width_px,
        height_px: sensor.height_px,
        principal_point_px: [sensor.cx_px, sensor.cy_px],
        mount_mm: sensor.mount_mm,
        samples: map.samples,
        horizon_px: map.horizon_px,
        elevation: map.elevation,
        fit,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sensor_is_traced_once_per_process() {
        let spec = SensorSpec::corner_paper("traced_once");
        let a = calibrate_sensor(&spec).unwrap();
        let b = calibrate_sensor(&spec).unwrap();
        assert_eq!(a, b);
        assert!(a.fit.is_some());
        let entries = TRACED
            .lock()
            .unwrap()
            .iter()
            .filter(|(s, _)| *s == spec)
            .count();
        assert_eq!(entries, 1);
    }
}
