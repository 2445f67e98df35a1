//! `[robot.timing]` and slip end to end: a late frame shows the world as it was the latency
//! ago and says when it was taken, lost frames are seeded and the robot carries on, a command
//! reaches the drive its latency later, and E1 on a late, blurred, defocused camera still
//! reaches its goal without contact.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{cpu, scenario};
use nalgebra::{Isometry2, Vector2};
use omniloop::run::render_snapshot;
use omniloop::{Simulation, run_scenario};
use omniloop_sim::Renderer;

#[test]
fn a_late_frame_shows_the_world_as_it_was_the_latency_ago() {
    let mut s = scenario("corner55_velocity_aware.toml");
    s.robot.sensors[0].noise_sigma = 0.0;
    s.robot.timing.frame_latency_s = 0.08; // two control periods
    let mut sim = Simulation::new(&s, &cpu(), |_| {}).unwrap();
    for _ in 0..40 {
        sim.step().unwrap();
    }
    sim.sense().unwrap();
    let frames = sim.frames();
    let frame = &frames[0];
    let now = sim.world().time_s();
    assert!(
        (now - frame.t_s - 0.08).abs() < 1e-9,
        "{} vs {now}",
        frame.t_s
    );
    // The truth two cycles ago (the trajectory's row of the cycle that started then).
    let rows = sim.trajectory();
    let then = &rows[rows.len() - 2];
    assert!((then.t_s - frame.t_s).abs() < 1e-9);
    let pose = Isometry2::new(Vector2::new(then.x_mm, then.y_mm), then.theta_rad);
    let mut r = Renderer::cpu();
    let expected = render_snapshot(&s, &mut r, None, Some(pose), false).unwrap();
    assert!(
        frame.image == &expected,
        "the frame is not the world 80 ms ago"
    );
    // The robot moved meanwhile: the frame at the pose now differs.
    let now_row = sim.trajectory().last().unwrap();
    let moved = (now_row.x_mm - then.x_mm).hypot(now_row.y_mm - then.y_mm);
    assert!(moved > 5.0, "{moved}");
}

#[test]
fn a_latency_between_periods_takes_the_frame_inside_its_cycle() {
    // 50 ms with 40 ms periods: rendered 30 ms into the cycle two periods before it arrives,
    // where the robot's velocity had carried it by v x 30 ms.
    let mut s = scenario("corner55_velocity_aware.toml");
    s.robot.timing.frame_latency_s = 0.05;
    let mut sim = Simulation::new(&s, &cpu(), |_| {}).unwrap();
    for _ in 0..30 {
        sim.step().unwrap();
    }
    sim.sense().unwrap();
    let t = sim.frames()[0].t_s;
    assert!((sim.world().time_s() - t - 0.05).abs() < 1e-9);
}

#[test]
fn lost_frames_are_seeded_and_the_robot_carries_on() {
    let mut s = scenario("corner55_velocity_aware.toml");
    s.robot.timing.frame_drop_rate = 0.3;
    let a = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap();
    let b = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap();
    assert_eq!(a.trajectory, b.trajectory);
    assert!(a.summary.reached_goal, "{:?}", a.summary);
    assert_eq!(a.summary.wall_contacts, 0);
    let lost = a
        .estimates
        .iter()
        .filter(|e| {
            e.not_found
                .iter()
                .any(|n| n.reason.starts_with("no frame of camera"))
        })
        .count() as f64;
    let share = lost / a.estimates.len() as f64;
    // 0.3 of about 210 frames: the binomial's sigma is 0.03.
    assert!((share - 0.3).abs() < 0.1, "{share}");
    let mut other = s.clone();
    other.seed += 1;
    let c = run_scenario(&other, &cpu(), |_| {}, |_, _| {}).unwrap();
    assert_ne!(a.trajectory, c.trajectory);
}

#[test]
fn a_command_reaches_the_drive_its_latency_later() {
    let first_motion = |latency: f64| {
        let mut s = scenario("corner55_velocity_aware.toml");
        s.robot.timing.command_latency_s = latency;
        s.run.duration_s = 1.0;
        let out = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap();
        out.trajectory
            .iter()
            .find(|r| r.vx_mm_s.hypot(r.vy_mm_s) > 1.0)
            .map(|r| r.t_s)
            .unwrap()
    };
    let (at_once, late) = (first_motion(0.0), first_motion(0.12));
    assert!(
        (late - at_once - 0.12).abs() < 1e-6,
        "{at_once} then {late}"
    );
}

#[test]
fn e1_on_a_late_blurred_defocused_camera_reaches_the_goal_without_contact() {
    let s = scenario("corner55_latency.toml");
    assert_eq!(s.robot.timing.frame_latency_s, 0.08);
    let m = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap().summary;
    assert!(m.reached_goal, "{m:?}");
    assert_eq!(m.wall_contacts, 0, "{m:?}");
    assert!(m.min_clearance_mm > 0.0, "{m:?}");
}
