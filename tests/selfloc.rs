//! E2 end to end: floor-region self-localization at the six places, and localization in the
//! loop across the field.

mod common;

use common::{cpu, scenario};
use omniloop::experiments::places::place_results;
use omniloop::run_scenario;
use omniloop_robot::PoseSource;

#[test]
fn e2_every_place_is_within_30_mm_and_1_degree_with_no_ambiguity_error() {
    let s = scenario("selfloc_field.toml");
    let out = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap();
    let places = place_results(&out.summary);
    assert_eq!(places.len(), 6);
    for p in &places {
        eprintln!(
            "place {:?}: RMS {:.1} mm, {:.2} deg, {} ambiguity errors, {} of {} not localized",
            p.true_pose,
            p.rms_position_mm,
            p.rms_heading_deg,
            p.ambiguity_errors,
            p.not_localized,
            p.frames
        );
        assert_eq!(p.frames, 10);
        assert_eq!(p.not_localized, 0, "{p:?}");
        assert_eq!(p.ambiguity_errors, 0, "{p:?}");
        assert!(p.rms_position_mm <= 30.0, "{p:?}");
        assert!(p.rms_heading_deg <= 1.0, "{p:?}");
    }
    // One trajectory row a frame, each with its estimate: every frame's fix was told apart from
    // its half-turn twin by the goals and set the robot's pose from nothing.
    assert_eq!(out.trajectory.len(), 60);
    assert!(out.trajectory.iter().all(|r| r.est_x_mm.is_some()));
    assert_eq!(out.summary.localization_fixes, Some(60));
}

#[test]
fn the_robot_crosses_the_field_through_its_waypoints_on_localization() {
    let s = scenario("field_waypoints.toml");
    let out = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap();
    let m = &out.summary;
    assert!(m.reached_goal, "{m:?}");
    assert_eq!(m.targets_reached, Some(4));
    assert_eq!(m.wall_contacts, 0, "{m:?}");
    // The pose it steered by stayed close to the truth, corrected by localization every cycle.
    assert!(m.pose_error_mm.unwrap() < 30.0, "{m:?}");
    assert!(
        m.localization_fixes.unwrap() as u64 >= m.cycles * 9 / 10,
        "{m:?}"
    );
}

#[test]
fn without_localization_the_same_run_drifts_several_times_further() {
    // The same crossing on its biased odometry alone (same noise): the estimate drifts from the
    // truth, by several times what localization leaves.
    let mut s = scenario("field_waypoints.toml");
    let with = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap().summary;
    s.control.pose_source = PoseSource::Odometry;
    let without = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap().summary;
    let (a, b) = (with.pose_error_mm.unwrap(), without.pose_error_mm.unwrap());
    eprintln!("median pose error: {a:.1} mm with localization, {b:.1} mm on odometry alone");
    assert!(b > 5.0 * a && b > 60.0, "{without:?} vs {with:?}");
}
