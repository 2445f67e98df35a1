//! A driving run stepped from outside (`Session`, what the Python package steps): the same
//! cycles as a whole run, commands from outside through `Remote`, refusals with reasons.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::common;

use common::{cpu, scenario};
use omniloop::robot::{BodyCommand, Remote, RobotSoftware};
use omniloop::run::{RunError, builtin_software};
use omniloop::{Runner, Session};
use omniloop_sim::RendererChoice;

#[test]
fn a_session_of_the_builtin_robot_stepped_to_its_end_is_the_whole_run() {
    let s = scenario("field_corners.toml");
    let whole = Runner::new(&s).renderer(RendererChoice::Cpu).run().unwrap();
    let mut session = Session::new(&s, &cpu(), builtin_software, |_| {}).unwrap();
    while !session.finished() {
        session.step().unwrap();
    }
    let out = session.output_with_files().unwrap();
    assert_eq!(out.trajectory, whole.trajectory);
    assert_eq!(out.summary.cycles, whole.summary.cycles);
    assert_eq!(out.summary.wall_contacts, whole.summary.wall_contacts);
    assert_eq!(out.summary.reached_goal, whole.summary.reached_goal);
    // The run is over: another step is refused, with the reason.
    let err = session.step().unwrap_err();
    assert!(matches!(err, RunError::Finished { .. }), "{err}");
}

#[test]
fn commands_from_outside_drive_the_robot() {
    let s = scenario("smoke.toml");
    let mut s = s.clone();
    s.run.pilot = omniloop::scenario::PilotChoice::Robot;
    let mut handle = None;
    let mut session = Session::new(
        &s,
        &cpu(),
        |config| {
            let (remote, h) = Remote::new(config, "outside");
            handle = Some(h);
            Ok(Box::new(remote) as Box<dyn RobotSoftware>)
        },
        |_| {},
    )
    .unwrap();
    let handle = handle.unwrap();
    let start = session.simulation().truth().pose.translation.x;
    handle.lock().command = BodyCommand::forward(300.0);
    for _ in 0..25 {
        session.step().unwrap();
    }
    let sim = session.simulation();
    let moved = sim.truth().pose.translation.x - start;
    assert!(moved > 100.0, "moved {moved} mm forward");
    let reading = sim.last_odometry().unwrap();
    assert!(reading.v_body_mm_s.x > 200.0, "{reading:?}");
    assert_eq!(session.output().summary.controller, "outside");
}

#[test]
fn an_experiment_with_a_procedure_of_its_own_cannot_be_stepped() {
    let s = scenario("selfloc_field.toml");
    let err = Session::new(&s, &cpu(), builtin_software, |_| {})
        .err()
        .expect("refused");
    let text = err.to_string();
    assert!(text.contains("cannot be stepped from outside"), "{text}");
    assert!(text.contains("places"), "{text}");
}
