//! The robot's software behind its sensor boundary: its mission moves on where its own
//! estimate says a target is reached, never where the truth does.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{cpu, scenario};
use nalgebra::{Point2, Vector2};
use omniloop::run_scenario;
use omniloop::scenario::OdometrySpec;

/// The odometry over-reads every distance by this fraction, and has no other error.
const SCALE_BIAS: f64 = 0.15;

#[test]
fn on_biased_odometry_the_robot_turns_where_its_estimate_says_the_waypoint_is() {
    let mut s = scenario("field_waypoints.toml");
    s.control.pose_source = omniloop_robot::ODOMETRY.into();
    s.odometry = OdometrySpec {
        speed_noise_frac: 0.0,
        omega_noise_rad_s: 0.0,
        scale_bias_frac: SCALE_BIAS,
        omega_bias_rad_s: 0.0,
        slip_s: 0.0,
    };
    s.run.duration_s = 8.0;
    let goal = s.goal.clone().unwrap();
    let waypoint = Point2::new(goal.waypoints_mm[0][0], goal.waypoints_mm[0][1]);
    let accept_mm = goal.tolerance_mm - goal.estimate_margin_mm;
    let start = s.start().point();
    let out = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap();

    // The first cycle heading for the second target: where the robot turned.
    let k = out
        .estimates
        .iter()
        .position(|e| e.target == Some(1))
        .expect("the robot moves on to its second waypoint");
    assert!(k > 0);
    let est = |i: usize| Point2::from(out.estimates[i].pose.unwrap().translation.vector);
    let truth = |i: usize| Point2::new(out.trajectory[i].x_mm, out.trajectory[i].y_mm);
    // It moved on in the first cycle its estimate came within reach of the waypoint.
    assert!((est(k) - waypoint).norm() <= accept_mm, "{}", est(k));
    assert!((est(k - 1) - waypoint).norm() > accept_mm);
    // The estimate is the dead reckoning of the biased odometry: the true displacement from the
    // start, over-read by the scale error (the robot does not turn, so no other error enters).
    let reckoned = start + (truth(k) - start) * (1.0 + SCALE_BIAS);
    let gap = (est(k) - reckoned).norm();
    eprintln!(
        "moved on at cycle {k}: estimate {:.1} mm from the waypoint, truth {:.1} mm; \
         estimate vs reckoned from the truth: {gap:.2} mm",
        (est(k) - waypoint).norm(),
        (truth(k) - waypoint).norm()
    );
    assert!(gap < 5.0, "estimate {} vs reckoned {reckoned}", est(k));
    // So the truth was well short of the waypoint when the robot turned for the next one...
    assert!((truth(k) - waypoint).norm() > goal.tolerance_mm);
    // ... and it never truly came within the tolerance while heading for it.
    let closest = (0..k)
        .map(|i| (truth(i) - waypoint).norm())
        .fold(f64::INFINITY, f64::min);
    assert!(closest > goal.tolerance_mm, "closest {closest}");
    assert_eq!(out.summary.targets_reached, Some(0));
    // From then on it heads for the second waypoint: its command points there by its estimate.
    let next = Point2::new(goal.waypoints_mm[1][0], goal.waypoints_mm[1][1]);
    let row = &out.trajectory[k];
    let cmd = Vector2::new(row.cmd_vx_mm_s, row.cmd_vy_mm_s);
    let to_next = next - est(k);
    assert!(
        cmd.dot(&to_next) > 0.0,
        "command {cmd} vs direction {to_next}"
    );
}
