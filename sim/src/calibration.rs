//! Tracing the image-to-floor map `r = f(R)` of a mirror sensor: for image radii R along the
//! image x axis, where the pixel's scene ray meets the floor, as distance from the sensor axis.

use crate::SimError;
use crate::optics::Optics;
use crate::sensor::Sensor;

/// `(R, r)` samples every `step_px` from 0 to just below the floor horizon, and the horizon's
/// image radius (found by bisection to 1e-6 px); none, and horizon 0, for a mirror that sees
/// no floor along the image x axis.
#[derive(Debug, Clone, PartialEq)]
pub struct RadialMap {
    /// `(R_px, r_mm)` pairs.
    pub samples: Vec<[f64; 2]>,
    /// Image radius beyond which rays no longer reach the floor.
    pub horizon_px: f64,
    /// `(R_px, elevation_rad)` every `step_px` from 0 to the mirror's edge in the image: the
    /// angle of the pixel's scene ray above the horizontal (negative: toward the floor).
    pub elevation: Vec<[f64; 2]>,
}

fn floor_distance(sensor: &Sensor, r_px: f64) -> Option<f64> {
    let ray = sensor.calibration_ray(r_px.max(1e-9), 0.0)?;
    let hit = ray.floor_hit()?;
    Some(hit.coords.xy().norm())
}

/// Traces the radial map of a mirror sensor (hyperbolic, conical or spherical).
pub fn trace_radial_map(sensor: &Sensor, step_px: f64) -> Result<RadialMap, SimError> {
    if matches!(sensor.optics, Optics::Pinhole(_)) {
        return Err(SimError::Invalid(format!(
            "sensor {:?} is a pinhole camera; the radial image-to-floor map exists for mirror \
             sensors only",
            sensor.name
        )));
    }
    if step_px.is_nan() || step_px <= 0.0 {
        return Err(SimError::Invalid(format!("step {step_px} px must be > 0")));
    }
    let r_max = sensor.width_px.max(sensor.height_px) as f64;
    // Last radius that still sees the floor, then bisect to the horizon.
    let mut lo = None;
    let mut k = 0;
    let mut samples = Vec::new();
    loop {
        let big_r = k as f64 * step_px;
        if big_r > r_max {
            break;
        }
        match floor_distance(sensor, big_r) {
            Some(r) if samples.last().is_none_or(|s: &[f64; 2]| r >= s[1]) => {
                samples.push([big_r, r]);
                lo = Some(big_r);
            }
            _ => break,
        }
        k += 1;
    }
    // A mirror that sees no floor (a conical one reflecting only sideways and up) still has
    // its elevation column: no floor samples, horizon 0.
    let Some(mut lo) = lo else {
        return Ok(RadialMap {
            samples,
            horizon_px: 0.0,
            elevation: trace_elevation(sensor, step_px, r_max),
        });
    };
    let mut hi = lo + step_px;
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if floor_distance(sensor, mid).is_some() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(RadialMap {
        samples,
        horizon_px: 0.5 * (lo + hi),
        elevation: trace_elevation(sensor, step_px, r_max),
    })
}

/// The elevation of the scene ray of image radius R along the image x axis, every `step_px`
/// from 0 while the camera sees the mirror.
fn trace_elevation(sensor: &Sensor, step_px: f64, r_max: f64) -> Vec<[f64; 2]> {
    (0..)
        .map(|k| k as f64 * step_px)
        .take_while(|&big_r| big_r <= r_max)
        .map_while(|big_r| {
            let ray = sensor.calibration_ray(big_r.max(1e-9), 0.0)?;
            Some([big_r, ray.dir.z.atan2(ray.dir.xy().norm())])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sensor::SensorSpec;

    #[test]
    fn the_corner_mirror_horizon_is_near_114_px() {
        let s = SensorSpec::corner_paper("omni").build();
        let map = trace_radial_map(&s, 0.25).unwrap();
        // A - B sqrt(C + R^2) = 0 at R = sqrt((A/B)^2 - C).
        let expected = ((10.12f64 / 2.054e-2).powi(2) - 2.298e5).sqrt();
        assert!(
            (map.horizon_px - expected).abs() < 0.5,
            "{}",
            map.horizon_px
        );
        assert!(map.samples.len() > 400);
        // A single viewpoint: the rays turn horizontal exactly at the floor horizon.
        let zero = map
            .elevation
            .windows(2)
            .find(|w| w[0][1] < 0.0 && w[1][1] >= 0.0)
            .unwrap();
        assert!(zero[0][0] <= map.horizon_px + 1e-9 && map.horizon_px <= zero[1][0]);
    }

    #[test]
    fn a_conical_mirror_that_sees_no_floor_still_has_its_elevations() {
        let spec = SensorSpec {
            optics: crate::optics::Optics::Conical(crate::optics::ConicalMirror {
                radius_mm: 30.0,
                tip_distance_mm: 100.0,
                focal_px: 300.0,
                lens_height_mm: 300.0,
                apex_angle_deg: 90.0,
            }),
            ..SensorSpec::corner_paper("cone")
        };
        let map = trace_radial_map(&spec.build(), 0.25).unwrap();
        assert!(map.samples.is_empty() && map.horizon_px == 0.0);
        assert!(map.elevation.len() > 10);
    }

    #[test]
    fn the_hemisphere_looks_down_at_its_centre_and_up_past_the_horizontal_at_its_rim() {
        let spec = SensorSpec {
            width_px: 256,
            height_px: 256,
            optics: crate::optics::Optics::Spherical(crate::optics::SphericalMirror {
                radius_mm: 30.0,
                camera_distance_mm: 150.0,
                focal_px: 530.0,
                lens_height_mm: 150.0,
            }),
            ..SensorSpec::corner_paper("hemi")
        };
        let map = trace_radial_map(&spec.build(), 0.25).unwrap();
        let e = &map.elevation;
        assert!((e[0][1] + std::f64::consts::FRAC_PI_2).abs() < 1e-6);
        assert!(
            e.windows(2).all(|w| w[1][1] > w[0][1]),
            "elevation rises outward"
        );
        assert!(e.last().unwrap()[1] > 0.0);
        // The floor horizon is where the rays turn horizontal (every ray pointing down meets
        // the floor plane somewhere).
        let zero = e
            .windows(2)
            .find(|w| w[0][1] < 0.0 && w[1][1] >= 0.0)
            .unwrap();
        assert!(zero[0][0] <= map.horizon_px + 1e-9 && map.horizon_px <= zero[1][0]);
    }
}
