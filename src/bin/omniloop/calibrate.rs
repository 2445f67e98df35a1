//! `omniloop calibrate`: a mirror sensor's traced image-to-floor map for the vision crate, or
//! a standard camera model fitted to its rays in a tool's file.

use super::load;
use anyhow::{Context, bail};
use omniloop::camera_export::{CameraFormat, export_camera_model};
use omniloop::report::output::default_out_dir;
use omniloop::scenario::calibrate::calibrate_sensor;
use omniloop::vision::RadialCalibration;
use omniloop_sim::SensorSpec;
use std::path::{Path, PathBuf};

/// `omniloop calibrate`'s arguments.
#[derive(clap::Args)]
pub struct CalibrateArgs {
    /// Scenario file.
    scenario: PathBuf,
    /// Sensor name (default: the robot's first sensor).
    #[arg(long)]
    sensor: Option<String>,
    /// Camera model file to write instead: opencv-omnidir or kalibr-omni (Mei's unified
    /// model), ocamcalib (Scaramuzza's polynomial) or kalibr-ds (double sphere);
    /// docs/camera-models.md.
    #[arg(long, value_parser = camera_format)]
    format: Option<CameraFormat>,
    /// Output file (default: runs/<scenario name>/calibration_<sensor>.json, or
    /// camera_<sensor>_<format>.yaml (.txt for ocamcalib) with --format; the model's pose
    /// as JSON beside it).
    #[arg(long)]
    out: Option<PathBuf>,
}

/// `omniloop calibrate`: the sensor's camera model file with `--format`, else its floor map.
pub fn calibrate_cmd(args: CalibrateArgs) -> anyhow::Result<()> {
    let CalibrateArgs {
        scenario,
        sensor,
        format,
        out,
    } = args;
    let s = load(&scenario)?;
    let spec = match s.sensor(sensor.as_deref()) {
        Ok(spec) => spec,
        Err(e) => bail!("scenario {:?}: {e}", s.name),
    };
    if let Some(format) = format {
        let out = out.unwrap_or_else(|| {
            let ext = if format == CameraFormat::Ocamcalib {
                "txt"
            } else {
                "yaml"
            };
            default_out_dir(&s).join(format!("camera_{}_{}.{ext}", spec.name, format.name()))
        });
        return write_camera_model(spec, format, &out);
    }
    let cal = calibrate_sensor(spec)?;
    let out =
        out.unwrap_or_else(|| default_out_dir(&s).join(format!("calibration_{}.json", spec.name)));
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
    }
    cal.save(&out)?;
    print_calibration(&spec.name, &cal);
    println!("written to {}", out.display());
    Ok(())
}

/// The floor map of sensor `name` in a few lines: its samples and horizon, the elevation of
/// its rays and the fitted form of f(R).
fn print_calibration(name: &str, cal: &RadialCalibration) {
    if cal.samples.is_empty() {
        println!(
            "sensor {}: sees no floor along its image x axis (no floor map)",
            name
        );
    } else {
        println!(
            "sensor {}: {} samples every 0.25 px, floor horizon at R = {:.2} px",
            name,
            cal.samples.len(),
            cal.horizon_px
        );
    }
    if let (Some(first), Some(last)) = (cal.elevation.first(), cal.elevation.last()) {
        println!(
            "elevation of the scene rays: {:.1} deg at R = 0 to {:.1} deg at R = {:.1} px",
            first[1].to_degrees(),
            last[1].to_degrees(),
            last[0]
        );
    }
    if let Some(f) = &cal.fit {
        println!(
            "f(R) = R / (A - B sqrt(C + R^2)), fitted for R <= {:.1} px:",
            0.95 * cal.horizon_px
        );
        println!("A= {:.4}", f.a);
        println!("B= {:.4e}", f.b);
        println!("C= {:.4e}", f.c);
        println!("rms residual {:.2e} mm", f.rms_mm);
    }
}

/// A camera model format by its command-line name.
fn camera_format(name: &str) -> Result<CameraFormat, String> {
    CameraFormat::ALL
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, f)| *f)
        .ok_or_else(|| {
            let names: Vec<&str> = CameraFormat::ALL.iter().map(|(n, _)| *n).collect();
            format!(
                "unknown camera model format {name:?} (one of: {})",
                names.join(", ")
            )
        })
}

/// Fits `format`'s model to `spec`'s rays, writes it to `out` and its pose as JSON beside it,
/// and prints the fit's residual.
fn write_camera_model(spec: &SensorSpec, format: CameraFormat, out: &Path) -> anyhow::Result<()> {
    let e = export_camera_model(spec, format)?;
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
    }
    std::fs::write(out, &e.text).with_context(|| format!("writing {}", out.display()))?;
    let json_path = out.with_extension("json");
    let json = serde_json::to_string_pretty(&e.json)?;
    std::fs::write(&json_path, json + "\n")
        .with_context(|| format!("writing {}", json_path.display()))?;
    println!(
        "sensor {} as {} ({}): reprojection RMS {:.4} px, worst {:.4} px over {} rays; rays \
         within {:.3} mm of the viewpoint",
        spec.name,
        format.name(),
        e.model.summary(),
        e.residual.rms_px,
        e.residual.worst_px,
        e.residual.count,
        e.viewpoint_spread_mm
    );
    println!("wrote {} and {}", out.display(), json_path.display());
    let t = e.pose.translation_mm.map(|v| (v * 1e6).round() / 1e6 + 0.0);
    let circle = e
        .image_circle_px
        .map_or(String::new(), |r| format!("\nimage_circle_px = {r:.4}"));
    println!(
        "as a sensor of a scenario (file relative to the scenario):\n\
         [robot.sensors.calibrated]\nfile = {:?}\nformat = \"{}\"\n\
         translation_mm = [{:?}, {:?}, {:?}]{circle}",
        out.display().to_string(),
        format.name(),
        t.x,
        t.y,
        t.z
    );
    Ok(())
}
