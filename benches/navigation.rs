//! Navigation benchmark: the planner's replan on the Small-Size field (20 mm cells, the
//! default) and the whole robot cycle with the planner, against the same cycle without it, at
//! 256x220 on the clutter benchmark's layouts (10 and 16 cubes).
//!
//! - Replan: the navigator's step (the free space of one frame into the grid, then a new plan,
//!   forced every call with a replan period shorter than a cycle) on the frames of a run along
//!   the clutter layout's route, beside the same step without a replan (the plan's cost is the
//!   difference): median and 90th percentile.
//! - Robot cycle: the built-in robot software's `cycle` (free space, localization, estimator,
//!   planner, controller; rendering and physics excluded) timed inside a closed-loop run, with
//!   `[control.planner] kind = "grid"` and `"none"`, side by side.
//!
//!     cargo bench --bench navigation
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use nalgebra::{Isometry2, Vector2};
use omniloop::robot::navigation::Navigator;
use omniloop::robot::{
    Observation, OdometryReading, Outputs, PlannerConfig, Robot, RobotConfig, RobotError,
    RobotSoftware,
};
use omniloop::scenario::calibrate::calibrate_sensor;
use omniloop::{Runner, Scenario, parse_scenario};
use omniloop_sim::{Renderer, RendererChoice, Scene, SensorNoise, World};
use omniloop_vision::FreeSpaceDetector;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// The clutter benchmark's scenario with `cubes` cubes and the planner `kind`.
fn clutter(cubes: usize, kind: &str) -> Scenario {
    let path = common::scenario_path("clutter.toml");
    let text = std::fs::read_to_string(&path)
        .expect("clutter.toml")
        .replace("cubes = 10", &format!("cubes = {cubes}"))
        .replace("kind = \"grid\"", &format!("kind = \"{kind}\""));
    parse_scenario(&text, &path, "clutter").expect("clutter scenario parses")
}

/// The built-in robot software, each `cycle` timed.
struct Timed {
    robot: Robot,
    times_ms: Arc<Mutex<Vec<f64>>>,
}

impl RobotSoftware for Timed {
    fn name(&self) -> String {
        self.robot.name()
    }
    fn cameras(&self) -> Vec<String> {
        self.robot.cameras()
    }
    fn cameras_now(&self) -> Vec<String> {
        self.robot.cameras_now()
    }
    fn cycle(&mut self, obs: &Observation<'_>) -> Result<Outputs, RobotError> {
        let t0 = Instant::now();
        let out = self.robot.cycle(obs);
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        self.times_ms.lock().expect("times").push(ms);
        out
    }
    fn odometry(&mut self, reading: &OdometryReading) {
        self.robot.odometry(reading);
    }
    fn forget_pose(&mut self) {
        self.robot.forget_pose();
    }
    fn estimate(&self) -> Option<Isometry2<f64>> {
        self.robot.estimate()
    }
}

/// Median and 90th percentile.
fn stats(mut v: Vec<f64>) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    (at(0.5), at(0.9))
}

/// The robot's cycle times in a closed-loop run of `s` (CPU renderer).
fn cycle_times(s: &Scenario) -> (Vec<f64>, omniloop::Summary) {
    let times = Arc::new(Mutex::new(Vec::new()));
    let shared = times.clone();
    let out = Runner::new(s)
        .renderer(RendererChoice::Cpu)
        .software(move |c: &RobotConfig| {
            Ok(Timed {
                robot: Robot::new(c)?,
                times_ms: shared.clone(),
            })
        })
        .run()
        .expect("run");
    let t = times.lock().expect("times").clone();
    (t, out.summary)
}

/// The navigator's step on the frames seen from the poses of a run of `s` (its true path,
/// every fifth cycle): with a replan forced every call, and with none after the first.
fn step_times(s: &Scenario) -> (Vec<f64>, Vec<f64>) {
    let run = Runner::new(s)
        .renderer(RendererChoice::Cpu)
        .run()
        .expect("run");
    let spec = &s.robot.sensors[0];
    let sensor = spec.build();
    let cal = calibrate_sensor(spec).expect("calibration");
    let mut detector = FreeSpaceDetector::new(s.vision.table("freespace").expect("settings"), &cal)
        .expect("detector");
    let config = s.robot_config(vec![cal.clone()], Vec::new());
    let settings: PlannerConfig = s.control.table("planner").expect("planner settings");
    let navigator = |replan_period_s: f64| {
        let planner = PlannerConfig {
            replan_period_s,
            ..settings.clone()
        };
        Navigator::new(&config, planner).expect("navigator")
    };
    let (mut forced, mut lazy) = (navigator(1e-6), navigator(1e9));
    let target = s.goal.as_ref().expect("goal").point();
    let mut renderer = Renderer::cpu();
    let mut noise = SensorNoise::new(1);
    let (mut with, mut without) = (Vec::new(), Vec::new());
    for (k, row) in run.trajectory.iter().enumerate().step_by(5) {
        let mut bodies = s.robot_bodies();
        bodies[0].start = Isometry2::new(Vector2::new(row.x_mm, row.y_mm), row.theta_rad);
        let world = World::new(&s.world, &bodies, 0.002).expect("world");
        let pose = world.robot_state(0).pose;
        let img = renderer
            .render(&Scene::of_world(&world), &sensor, &pose, Some(&mut noise))
            .expect("render");
        let fs = detector.detect(&img).expect("detect");
        let t_s = k as f64 * 0.04;
        for (nav, times) in [(&mut forced, &mut with), (&mut lazy, &mut without)] {
            let t0 = Instant::now();
            let _ = nav.steer(Some(&fs), &pose, Vector2::zeros(), target, t_s);
            times.push(t0.elapsed().as_secs_f64() * 1e3);
        }
    }
    (with, without)
}

fn main() {
    println!(
        "{:<52} {:>10} {:>8} {:>8}",
        "clutter layout 1, 256x220, CPU", "median ms", "p90 ms", "samples"
    );
    for cubes in [10, 16] {
        let s = clutter(cubes, "grid");
        let (with, without) = step_times(&s);
        let n = with.len();
        for (what, t) in [
            ("grid update + replan", with),
            ("grid update, no replan", without),
        ] {
            let (m, p) = stats(t);
            println!(
                "{:<52} {:>10.3} {:>8.3} {:>8}",
                format!("{cubes} cubes: {what} (20 mm cells)"),
                m,
                p,
                n
            );
        }
        for kind in ["grid", "none"] {
            let (t, summary) = cycle_times(&clutter(cubes, kind));
            let len = t.len();
            let (m, p) = stats(t);
            println!(
                "{:<52} {:>10.3} {:>8.3} {:>8}",
                format!(
                    "{cubes} cubes: robot cycle, planner {kind} (goal {})",
                    if summary.reached_goal {
                        "reached"
                    } else {
                        "missed"
                    }
                ),
                m,
                p,
                len
            );
        }
    }
}
