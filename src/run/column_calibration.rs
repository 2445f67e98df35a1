//! Calibrating a panning pinhole camera's columns as the resection paper does (Sect. 3.2): the
//! camera, level and at pan 0, takes two images of a target of equally spaced vertical black
//! and white stripes square to its axis, from 2 m and from 1 m, with its own noise and grey
//! levels; [`ColumnCalibration::measure`] finds the axis column and the focal length in them.
//! Nothing is read from the optics.

use super::cameras::sensor_noise_seed;
use super::error::RunError;
use nalgebra::Isometry2;
use omniloop_sim::optics::Optics;
use omniloop_sim::{Board, Layout, Renderer, Rgb, Scene, SensorNoise, SensorSpec, SimError};
use omniloop_vision::resection::{ColumnCalibration, LineTarget};

/// Stripes each side of the target's reference stripe.
const SIDE_STRIPES: usize = 60;

/// Measures the column calibration of the pinhole camera `spec` (noise drawn from `seed`).
pub fn calibrate_columns(spec: &SensorSpec, seed: u64) -> Result<ColumnCalibration, RunError> {
    let mut sensor = spec.build();
    let Optics::Pinhole(cam) = &mut sensor.optics else {
        return Err(SimError::Invalid(format!(
            "sensor {:?} is not a pinhole camera: its columns have no single bearing",
            spec.name
        ))
        .into());
    };
    cam.pan_deg = 0.0;
    cam.tilt_deg = 0.0;
    let target = LineTarget::default();
    let mut renderer = Renderer::cpu();
    let mut noise = SensorNoise::new(sensor_noise_seed(seed, 1000));
    let mut view = |depth_mm: f64| {
        let scene = Scene::new(&target_layout(&target, sensor.mount_mm[0] + depth_mm), &[]);
        renderer.render(&scene, &sensor, &Isometry2::identity(), Some(&mut noise))
    };
    let far = view(target.far_mm)?;
    let near = view(target.near_mm)?;
    let mut cal = ColumnCalibration::measure(&spec.name, &far, &near, &target)?;
    cal.mount_mm = sensor.mount_mm;
    Ok(cal)
}

/// An empty room with the target's face square to the x axis at `face_mm`, centred on it.
fn target_layout(target: &LineTarget, face_mm: f64) -> Layout {
    let stripes = LineTarget::stripes(SIDE_STRIPES);
    let half = 0.5 * stripes.iter().sum::<f64>() * target.stripe_mm;
    let thickness_mm = 10.0;
    let x_mm = face_mm + 0.5 * thickness_mm;
    Layout {
        floor_rgb: Rgb([150, 150, 150]),
        boards: vec![Board {
            name: None,
            from_mm: [x_mm, half],
            to_mm: [x_mm, -half],
            bottom_mm: 0.0,
            top_mm: 3000.0,
            thickness_mm,
            stripes,
            rgb_a: Rgb([15, 15, 15]),
            rgb_b: Rgb([245, 245, 245]),
        }],
        ..Layout::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_paper_camera_is_measured_at_its_axis_and_focal_length() {
        let text = "name = \"pan\"\nwidth_px = 256\nheight_px = 256\n\
                    principal_point_px = [148.0, 128.0]\ngrey_levels = 16\n\
                    [pinhole]\nfocal_px = 516.0\nheight_mm = 280.0\n";
        let spec: SensorSpec = toml::from_str(text).unwrap();
        let cal = calibrate_columns(&spec, 5).unwrap();
        eprintln!("{cal:?}, {:.3} px a degree", cal.px_per_deg());
        // Column i is sample i, whose centre is at i + 0.5 from the image's left edge.
        assert!(
            (cal.axis_column_px + 0.5 - 148.0).abs() < 0.3,
            "axis {}",
            cal.axis_column_px
        );
        assert!((cal.focal_px - 516.0).abs() < 0.5, "focal {}", cal.focal_px);
    }
}
