//! Standard camera models in and out, end to end: the corner paper's hyperbolic sensor
//! exported to each central format (its viewpoint the mirror's focus, the unified model exact
//! for it) and imported again as a `calibrated` sensor renders the analytic mirror's frames
//! (CPU and GPU), drives E1 to its goal, and a bad calibration file stops a scenario with its
//! file, line and field. The four fits are made once for the whole file (seconds each).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{assert_alike, bin, cpu, gpu_or_skip, scenario, scenario_path, tmp};
use nalgebra::{Isometry2, Matrix3, Vector2};
use omniloop::Scenario;
use omniloop::camera_export::{CameraExport, CameraFormat, FittedModel, export_camera_model};
use omniloop::run::render_snapshot;
use omniloop::run_scenario;
use omniloop_sim::Renderer;
use omniloop_sim::SensorSpec;
use omniloop_sim::optics::{CalibratedCamera, HyperbolicMirror, Optics};
use std::path::Path;
use std::sync::OnceLock;

/// The E1 corner at its start and near its inner tip, where the walls fill the view.
fn poses() -> [Option<Isometry2<f64>>; 2] {
    [
        None,
        Some(Isometry2::new(
            Vector2::new(-650.0, 150.0),
            40f64.to_radians(),
        )),
    ]
}

/// E1's sensor exported as `format`: fitted once for the tests of this file that share it (a
/// fit takes seconds).
fn exported(format: CameraFormat) -> &'static CameraExport {
    static EXPORTS: OnceLock<Vec<(CameraFormat, CameraExport)>> = OnceLock::new();
    let exports = EXPORTS.get_or_init(|| {
        let s = scenario("corner55_velocity_aware.toml");
        let spec = &s.robot.sensors[0];
        let export = |(_, f): (&str, CameraFormat)| (f, export_camera_model(spec, f).unwrap());
        CameraFormat::ALL.into_iter().map(export).collect()
    });
    &exports.iter().find(|(f, _)| *f == format).unwrap().1
}

/// E1's scenario with its sensor exported as `format` into `dir` and imported again.
fn reimported(format: CameraFormat, dir: &Path) -> Scenario {
    let mut s = scenario("corner55_velocity_aware.toml");
    let e = exported(format);
    assert!(
        e.residual.worst_px < 0.05,
        "{}: {:?}",
        format.name(),
        e.residual
    );
    let file = dir.join(format!("omni.{}", format.name()));
    std::fs::write(&file, &e.text).unwrap();
    // The model frame's rotation as the file's comments state it (the format's default).
    let rows = |m: &Matrix3<f64>| [0, 1, 2].map(|i| [m[(i, 0)], m[(i, 1)], m[(i, 2)]]);
    let t = e.pose.translation_mm;
    let cam = CalibratedCamera::from_file(
        &file,
        format.name(),
        Some(rows(&e.pose.rotation)),
        [t.x, t.y, t.z],
        e.image_circle_px,
    )
    .unwrap();
    s.robot.sensors[0].optics = Optics::Calibrated(cam);
    s
}

#[test]
fn the_hyperbolic_mirror_is_central_and_the_unified_model_exact_for_it() {
    // E1's sensor is the corner paper's.
    let spec = &scenario("corner55_velocity_aware.toml").robot.sensors[0];
    assert_eq!(spec, &SensorSpec::corner_paper("omni"));
    let e = exported(CameraFormat::OpencvOmnidir);
    assert!(e.residual.count > 20_000, "{:?}", e.residual);
    assert!(e.residual.worst_px < 0.05, "{:?}", e.residual);
    assert!(e.viewpoint_spread_mm < 1e-6, "{}", e.viewpoint_spread_mm);
    // The viewpoint is the upper focus, 205.08 mm above the floor on the axis.
    let t = e.pose.translation_mm;
    assert!(t.xy().norm() < 1e-9 && (t.z - 205.08).abs() < 1e-9, "{t}");
    // xi = 2e / (1 + e^2) with e = c / b (Geyer and Daniilidis).
    let m = HyperbolicMirror::corner_paper();
    let ecc = m.focal_half_distance_mm() / m.b_mm;
    let FittedModel::Unified(m) = &e.model else {
        panic!("{:?}", e.model)
    };
    assert!((m.xi - 2.0 * ecc / (1.0 + ecc * ecc)).abs() < 1e-4, "{m:?}");
    // The double sphere model holds the unified one: exact too.
    let ds = exported(CameraFormat::KalibrDs);
    assert!(ds.residual.worst_px < 0.05, "{:?}", ds.residual);
    assert!(ds.text.contains("camera_model: ds"), "{}", ds.text);
    // Scaramuzza's polynomial approximates it (degree 4, its inverse to 0.01 px).
    let ocam = exported(CameraFormat::Ocamcalib);
    assert!(ocam.residual.worst_px < 0.05, "{:?}", ocam.residual);
    assert!(
        ocam.text.starts_with("#polynomial coefficients"),
        "{}",
        ocam.text
    );
}

#[test]
fn the_hyperbolic_sensor_exported_and_imported_renders_the_analytic_mirrors_frames() {
    let dir = tmp("camera_models_round_trip");
    let analytic = scenario("corner55_velocity_aware.toml");
    let mut r = Renderer::cpu();
    for (_, format) in CameraFormat::ALL {
        let s = reimported(format, &dir);
        for pose in poses() {
            let a = render_snapshot(&analytic, &mut r, None, pose, false).unwrap();
            let b = render_snapshot(&s, &mut r, None, pose, false).unwrap();
            assert_alike(&a, &b, 1, format.name());
            // Not trivially: the frames are not black.
            assert!(b.pixels().filter(|p| p.0[..3] != [0, 0, 0]).count() > 50_000);
        }
    }
}

#[test]
fn calibrated_cameras_render_alike_on_the_gpu_and_the_cpu() {
    let Some(mut gpu) = gpu_or_skip() else {
        return;
    };
    let dir = tmp("camera_models_gpu");
    let mut cpu_renderer = Renderer::cpu();
    for (_, format) in CameraFormat::ALL {
        let s = reimported(format, &dir);
        for pose in poses() {
            let a = render_snapshot(&s, &mut cpu_renderer, None, pose, true).unwrap();
            let b = render_snapshot(&s, &mut gpu, None, pose, true).unwrap();
            assert_alike(&a, &b, 2, &format!("{} ({})", format.name(), gpu.name()));
        }
    }
}

#[test]
fn e1_on_the_camera_reimported_from_its_opencv_file_reaches_the_goal_without_contact() {
    let s = scenario("corner55_calibrated.toml");
    assert_eq!(s.robot.sensors[0].optics.kind(), "calibrated");
    let m = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap().summary;
    assert!(m.reached_goal, "{m:?}");
    assert_eq!(m.wall_contacts, 0, "{m:?}");
    assert!(m.min_clearance_mm > 0.0, "{m:?}");
}

/// `omniloop check` of the calibrated E1 scenario with its camera file as `text`, in `format`:
/// the exit code and the message.
fn check_with(name: &str, text: &str, format: &str) -> (i32, String) {
    let dir = tmp(name);
    std::fs::create_dir_all(dir.join("cameras")).unwrap();
    std::fs::write(dir.join("cameras/corner_omni.opencv.yaml"), text).unwrap();
    let scenario_text = std::fs::read_to_string(scenario_path("corner55_calibrated.toml"))
        .unwrap()
        .replace(
            "format = \"opencv-omnidir\"",
            &format!("format = \"{format}\""),
        );
    let file = dir.join("calibrated.toml");
    std::fs::write(&file, scenario_text).unwrap();
    let out = bin().arg("check").arg(&file).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr),
    )
}

#[test]
fn a_bad_calibration_file_exits_2_naming_the_file_line_and_field() {
    let good = std::fs::read_to_string(scenario_path("cameras/corner_omni.opencv.yaml")).unwrap();
    let (code, text) = check_with("bad_camera_good", &good, "opencv-omnidir");
    assert_eq!(code, 0, "{text}");
    // A missing field.
    let (code, text) = check_with(
        "bad_camera_missing",
        &good.replace("\nxi:", "\nchi:"),
        "opencv-omnidir",
    );
    assert_eq!(code, 2, "{text}");
    assert!(
        text.contains("calibrated.toml:")
            && text.contains("field `robot.sensors[0].calibrated.file`")
            && text.contains("corner_omni.opencv.yaml: line ")
            && text.contains("field `xi`: missing"),
        "{text}"
    );
    // The wrong format: an OpenCV file read as OCamCalib's.
    let (code, text) = check_with("bad_camera_format", &good, "ocamcalib");
    assert_eq!(code, 2, "{text}");
    assert!(
        text.contains("line 1, field `pol`: expected numbers"),
        "{text}"
    );
    // A polynomial whose rays turn back inside the image: world2cam has no real root there.
    let e = exported(CameraFormat::Ocamcalib);
    let pol_line = e.text.lines().position(|l| l.starts_with("5 ")).unwrap();
    let bent: String = e
        .text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == pol_line {
                "5 -1.0e2 0.0 1.0e-3 0.0 -1.0e-7\n".to_string()
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let (code, text) = check_with("bad_camera_polynomial", &bent, "ocamcalib");
    assert_eq!(code, 2, "{text}");
    assert!(
        text.contains(&format!(
            "line {}, field `pol`: f(rho) - rho tan(theta) has no real root",
            pol_line + 1
        )),
        "{text}"
    );
}
