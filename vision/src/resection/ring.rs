//! The marks all round the robot from one omnidirectional image (beyond the paper, which pans
//! a camera): a vertical stripe of a board images as a radial segment, so the paper's band of
//! rows becomes a ring of image radii between two elevations, and its column profile an angular
//! profile, each sample the mean luminance along the ring's radii at one azimuth (bilinear). The
//! same stripe matcher reads it, wrapped round. The profile runs clockwise (decreasing bearing)
//! so that, like an image row, it reads a mark from its left to its right as the robot sees it.

use super::columns::bilinear;
use crate::{RadialCalibration, VisionError};
use image::RgbaImage;
use std::f64::consts::TAU;

/// The angular profile of `image` over the ring between elevations `elevation_deg[0]` and
/// `[1]` (degrees above the horizontal, through `calibration`'s elevation table): `samples`
/// azimuths from 0 (the robot's x axis) clockwise, `radii` radii each.
pub fn ring_profile(
    image: &RgbaImage,
    calibration: &RadialCalibration,
    elevation_deg: [f64; 2],
    samples: usize,
    radii: usize,
) -> Result<Vec<f32>, VisionError> {
    let radius = |e: f64| {
        calibration
            .radius_at_elevation_px(e.to_radians())
            .ok_or_else(|| {
                VisionError::Calibration(format!(
                    "camera {:?} sees no scene at {e} degrees of elevation",
                    calibration.sensor
                ))
            })
    };
    let (r0, r1) = (radius(elevation_deg[0])?, radius(elevation_deg[1])?);
    let [cx, cy] = calibration.principal_point_px;
    let rs: Vec<f64> = (0..radii)
        .map(|k| r0 + (r1 - r0) * (k as f64 + 0.5) / radii as f64)
        .collect();
    let mut out = Vec::with_capacity(samples);
    for s in 0..samples {
        let (sin, cos) = ring_bearing_rad(s as f64, samples).sin_cos();
        let (mut sum, mut n) = (0.0f32, 0u32);
        for r in &rs {
            // Image coordinates (X, Y up) to pixel-centre coordinates.
            let (u, v) = (cx + r * cos - 0.5, cy - r * sin - 0.5);
            if let Some(l) = bilinear(image, u, v) {
                sum += l;
                n += 1;
            }
        }
        if n == 0 {
            return Err(VisionError::NotFound(format!(
                "the ring at {:.0}-{:.0} px leaves the image",
                r0, r1
            )));
        }
        out.push(sum / n as f32);
    }
    Ok(out)
}

/// The bearing of profile position `at` (samples) in a profile of `samples`, rad: clockwise
/// from the robot's x axis.
pub fn ring_bearing_rad(at: f64, samples: usize) -> f64 {
    -TAU * at / samples as f64
}
