//! Camera effects on rendered frames: each knob changes a frame the way it should (motion blur
//! spreads a floor edge over the image radii it crossed during the exposure, defocus widens a
//! step edge by the Gaussian's width, vignetting lowers the rim by its fraction), and the GPU
//! and the CPU renderer give the same frames with the effects on.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{assert_alike, gpu_or_skip, paper_f, paper_f_inverse, scenario};
use image::RgbaImage;
use nalgebra::{Isometry2, Vector2};
use omniloop::run::render_snapshot;
use omniloop_sim::render::effects::exposure_poses;
use omniloop_sim::{CameraEffects, FloorRect, Layout, Renderer, Scene, SensorSpec};

/// A floor stripe (floor colour) from `near` to `far` mm ahead of the robot on the outside
/// colour, and nothing else.
fn stripe(near: f64, far: f64) -> Layout {
    Layout {
        floor_rects: vec![FloorRect {
            center_mm: [(near + far) / 2.0, 0.0],
            size_mm: [far - near, 400.0],
            angle_deg: 0.0,
        }],
        ..Layout::default()
    }
}

/// The red levels of row 109 (pixel centres at Y = +0.5, by the principal point).
fn row(img: &RgbaImage) -> Vec<f64> {
    (0..img.width())
        .map(|u| img.get_pixel(u, 109).0[0] as f64)
        .collect()
}

#[test]
fn motion_blur_spreads_a_floor_edge_over_the_radii_it_crossed() {
    // The robot drives +x at 400 mm/s; over a 50 ms exposure the stripe's near edge, 600 mm
    // ahead at the end, was up to 20 mm farther. A pixel at image radius X sees the stripe in
    // the sub-frames j where 600 + v s_j <= f(X) <= 800 + v s_j.
    let layout = stripe(600.0, 800.0);
    let scene = Scene::new(&layout, &[]);
    let mut spec = SensorSpec::corner_paper("omni");
    spec.effects = CameraEffects {
        exposure_s: 0.05,
        exposure_samples: 8,
        ..CameraEffects::default()
    };
    let sensor = spec.build();
    let pose = Isometry2::new(Vector2::zeros(), 0.0);
    let v = Vector2::new(400.0, 0.0);
    let poses = exposure_poses(&pose, v, 0.0, &sensor.effects);
    assert_eq!(poses.len(), 8);
    let mut r = Renderer::cpu();
    let blurred = row(&r.render_exposed(&scene, &sensor, &poses, None).unwrap());
    let sharp = row(&r
        .render(
            &scene,
            &SensorSpec::corner_paper("omni").build(),
            &pose,
            None,
        )
        .unwrap());
    let (floor, outside) = (layout.floor_rgb.0[0] as f64, layout.outside_rgb.0[0] as f64);
    let (x_near, x_far) = (paper_f_inverse(600.0), paper_f_inverse(620.0));
    let mut mixed = 0;
    let mut sharp_mixed = 0;
    let is_mixed = |l: f64| (l - floor).abs() > 1.0 && (l - outside).abs() > 1.0;
    for (u, level) in blurred.iter().enumerate() {
        let x = u as f64 + 0.5 - 128.0;
        if !(x_near - 3.0..=x_far + 3.0).contains(&x) {
            continue;
        }
        if is_mixed(sharp[u]) {
            sharp_mixed += 1;
        }
        let d = paper_f(x);
        let seen = (0..8)
            .filter(|j| {
                let s = 0.05 * (*j as f64 + 0.5) / 8.0;
                (600.0 + 400.0 * s..=800.0 + 400.0 * s).contains(&d)
            })
            .count() as f64;
        let want = (seen * floor + (8.0 - seen) * outside) / 8.0;
        // A sub-frame's edge within the f(R) reconstruction's 0.05 px of a pixel centre could
        // flip one sub-frame: one eighth of the contrast.
        assert!(
            (level - want).abs() <= 1.0 + (floor - outside).abs() / 8.0,
            "pixel {u} (X = {x:.2}): {level} vs {want}"
        );
        if is_mixed(*level) {
            mixed += 1;
        }
    }
    // The edge moved by 2.7 px in the image: as many pixels are mixed, against none sharp.
    let spread = x_far - x_near;
    assert!(
        (mixed as f64 - spread).abs() <= 1.0,
        "{mixed} mixed pixels, the edge crossed {spread:.2} px"
    );
    assert_eq!(sharp_mixed, 0);
}

#[test]
fn defocus_widens_a_step_edge_by_the_gaussians_width() {
    // The stripe's far edge at 1000 mm, a radial step in the image; along the row the 10-90%
    // rise of a Gaussian blur is 2 x 1.2816 sigma.
    let layout = stripe(300.0, 1000.0);
    let scene = Scene::new(&layout, &[]);
    let pose = Isometry2::new(Vector2::zeros(), 0.0);
    let mut r = Renderer::cpu();
    let (floor, outside) = (layout.floor_rgb.0[0] as f64, layout.outside_rgb.0[0] as f64);
    let edge_u = (paper_f_inverse(1000.0) + 128.0) as usize;
    for sigma in [1.0, 2.0] {
        let mut spec = SensorSpec::corner_paper("omni");
        spec.effects = CameraEffects {
            defocus_px: sigma,
            ..CameraEffects::default()
        };
        let levels = row(&r.render(&scene, &spec.build(), &pose, None).unwrap());
        let lo = floor.min(outside) + 0.1 * (floor - outside).abs();
        let hi = floor.max(outside) - 0.1 * (floor - outside).abs();
        let window = &levels[edge_u - 8..edge_u + 8];
        let rise = window.iter().filter(|l| (lo..=hi).contains(*l)).count() as f64;
        let want = 2.0 * 1.2816 * sigma;
        assert!(
            (rise - want).abs() <= 1.0,
            "sigma {sigma}: {rise} px between 10% and 90%, want {want:.2}"
        );
    }
}

#[test]
fn vignetting_lowers_the_rim_by_its_fraction() {
    // A floor that fills the view: one level everywhere until vignetting darkens the rim of the
    // image circle (110 px about the principal point) by 30%.
    let layout = stripe(-3000.0, 3000.0);
    let layout = Layout {
        floor_rects: vec![FloorRect {
            size_mm: [6000.0, 6000.0],
            ..layout.floor_rects[0].clone()
        }],
        ..layout
    };
    let scene = Scene::new(&layout, &[]);
    let mut spec = SensorSpec::corner_paper("omni");
    spec.effects = CameraEffects {
        vignetting: 0.3,
        ..CameraEffects::default()
    };
    let pose = Isometry2::new(Vector2::zeros(), 0.0);
    let img = Renderer::cpu()
        .render(&scene, &spec.build(), &pose, None)
        .unwrap();
    let centre = img.get_pixel(128, 109).0[0] as f64;
    assert!(
        (centre - layout.floor_rgb.0[0] as f64).abs() <= 1.0,
        "{centre}"
    );
    for (u, v) in [(128 + 99, 109), (128 - 100, 109), (128, 109 - 99)] {
        let (x, y) = (u as f64 + 0.5 - 128.0, 110.0 - (v as f64 + 0.5));
        let want = centre * (1.0 - 0.3 * (x * x + y * y) / (110.0 * 110.0));
        let got = img.get_pixel(u, v).0[0] as f64;
        assert!((got - want).abs() <= 1.0, "({u}, {v}): {got} vs {want}");
    }
}

#[test]
fn the_gpu_and_the_cpu_develop_the_same_frames_with_the_effects_on() {
    let Some(mut gpu) = gpu_or_skip() else {
        return;
    };
    let mut s = scenario("corner55_velocity_aware.toml");
    s.robot.sensors[0].effects = CameraEffects {
        illumination: 0.8,
        vignetting: 0.2,
        defocus_px: 1.0,
        gain: 1.3,
        jpeg_quality: 90,
        ..CameraEffects::default()
    };
    let mut cpu = Renderer::cpu();
    let a = render_snapshot(&s, &mut cpu, None, None, true).unwrap();
    let b = render_snapshot(&s, &mut gpu, None, None, true).unwrap();
    assert_alike(&a, &b, 2, gpu.name());
    // The effects did something: the frame differs from the one without them.
    let plain = render_snapshot(
        &scenario("corner55_velocity_aware.toml"),
        &mut cpu,
        None,
        None,
        true,
    )
    .unwrap();
    let same = a
        .pixels()
        .zip(plain.pixels())
        .filter(|(p, q)| p == q)
        .count();
    assert!(same < (a.width() * a.height()) as usize / 2, "{same}");
}
