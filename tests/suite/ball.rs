//! The ball in the world against closed form: kicks from a robot's kicker, a chip's landing, a
//! wall's bounce, the dribbler through a turn; and the shipped ball scenarios.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{check_variant, cpu, omniloop, scenario, tmp};

use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_control::VelocityCommand;
use omniloop_sim::ball::GRAVITY_MM_S2;
use omniloop_sim::{
    BallCommand, BallEvent, BallSpec, Kick, KickerSpec, Layout, Rgb, RobotBodySpec, Wall, World,
};

const STEP_S: f64 = 0.002;

fn striker(x: f64, y: f64, heading: f64) -> RobotBodySpec {
    RobotBodySpec {
        start: Isometry2::new(Vector2::new(x, y), heading),
        radius_mm: 90.0,
        height_mm: 150.0,
        accel_limit_mm_s2: 6000.0,
        angular_accel_limit_rad_s2: 40.0,
        max_speed_mm_s: 3000.0,
        rgb: Rgb([20, 20, 20]),
        marking_rgb: None,
        differential: None,
        kicker: Some(KickerSpec::default()),
    }
}

/// A ball touching the front of a robot at the origin facing +x.
fn ball_at_front(extra: Layout) -> Layout {
    let k = KickerSpec::default();
    let spec = BallSpec::default();
    Layout {
        ball: Some(BallSpec {
            center_mm: [k.front_mm + spec.radius_mm, 0.0],
            ..spec
        }),
        ..extra
    }
}

fn kick(world: &mut World, speed_mm_s: f64, angle_deg: f64) {
    world.set_ball_command(
        0,
        BallCommand {
            kick: Some(Kick {
                speed_mm_s,
                angle_rad: angle_deg.to_radians(),
            }),
            dribbler_rpm: 0.0,
        },
    );
}

#[test]
fn flat_kicks_from_a_kicker_rest_where_the_two_phase_model_says() {
    for v0 in [1000.0, 3000.0, 6500.0] {
        let layout = ball_at_front(Layout::default());
        let mut w = World::new(&layout, &[striker(0.0, 0.0, 0.0)], STEP_S).unwrap();
        let start = w.ball().unwrap().1.position_mm;
        kick(&mut w, v0, 0.0);
        let mut t_kick = None;
        let mut t = 0.0;
        while t < 30.0 {
            w.advance(STEP_S);
            t += STEP_S;
            let b = w.ball().unwrap().1;
            if t_kick.is_none() && b.velocity_mm_s.norm() > 0.0 {
                t_kick = Some(t);
            }
            if t_kick.is_some() && b.velocity_mm_s.norm() == 0.0 {
                break;
            }
        }
        let (spec, b) = w.ball().unwrap();
        let (d0, t0) = spec.rest_after_kick(v0);
        let d = (b.position_mm - start).norm();
        let took = t - t_kick.unwrap() + STEP_S;
        assert!((d - d0).abs() <= 0.02 * d0, "{v0}: {d} mm against {d0}");
        assert!(
            (took - t0).abs() <= 0.02 * t0,
            "{v0}: {took} s against {t0}"
        );
        let kicks: Vec<_> = (w.ball_events().iter())
            .filter(|e| matches!(e, BallEvent::Kick { .. }))
            .collect();
        assert_eq!(kicks.len(), 1, "{:?}", w.ball_events());
        // It flew straight ahead.
        assert!(b.position_mm.y.abs() < 1e-6, "{:?}", b.position_mm);
    }
}

#[test]
fn a_chip_lands_where_the_ballistic_flight_does_and_flies_over_a_robot() {
    let speed = 4000.0f64;
    let angle = 45f64.to_radians();
    let landing = speed * angle.cos() * 2.0 * speed * angle.sin() / GRAVITY_MM_S2;
    // A second robot 600 mm ahead, 150 mm tall: the ball is far above it by then.
    let layout = ball_at_front(Layout::default());
    let robots = [
        striker(0.0, 0.0, 0.0),
        striker(700.0, 0.0, std::f64::consts::PI),
    ];
    let mut w = World::new(&layout, &robots, STEP_S).unwrap();
    let start = w.ball().unwrap().1.position_mm;
    kick(&mut w, speed, 45.0);
    let mut landed = None;
    for _ in 0..2000 {
        let before = w.ball().unwrap().1.vz_mm_s;
        w.advance(STEP_S);
        let b = w.ball().unwrap().1;
        if before < 0.0 && b.vz_mm_s >= 0.0 {
            landed = Some(b.position_mm.x - start.x);
            break;
        }
    }
    let x = landed.expect("the chip lands");
    assert!(
        (x - landing).abs() <= 0.02 * landing,
        "{x} mm against {landing}"
    );
    assert!(
        !(w.ball_events().iter()).any(|e| matches!(e, BallEvent::Touch { robot: 1, .. })),
        "{:?}",
        w.ball_events()
    );
}

#[test]
fn a_ball_bounces_off_a_wall_with_the_restitution() {
    for restitution in [0.3, 0.5, 0.8] {
        let layout = Layout {
            walls: vec![Wall {
                from_mm: [1000.0, -500.0],
                to_mm: [1000.0, 500.0],
                thickness_mm: 100.0,
                height_mm: 150.0,
                rgb: Rgb([235, 235, 235]),
            }],
            ball: Some(BallSpec {
                center_mm: [800.0, 0.0],
                velocity_mm_s: [2000.0, 0.0],
                restitution,
                ..BallSpec::default()
            }),
            ..Layout::default()
        };
        let mut w = World::new(&layout, &[], STEP_S).unwrap();
        let mut before = 0.0;
        let mut after = None;
        for _ in 0..500 {
            let v = w.ball().unwrap().1.velocity_mm_s.x;
            w.advance(STEP_S);
            let now = w.ball().unwrap().1.velocity_mm_s.x;
            if v > 0.0 && now < 0.0 {
                before = v;
                after = Some(-now);
                break;
            }
        }
        let after = after.expect("it bounces");
        // The speed just before the step of the bounce, less one step's deceleration.
        let expected = restitution * before;
        assert!(
            (after - expected).abs() <= 0.02 * expected,
            "{restitution}: {after} against {expected}"
        );
        // Not through the wall: its face is at 950 mm.
        assert!(w.ball().unwrap().1.position_mm.x < 950.0 - 21.0);
    }
}

/// Drives the striker holding the ball at 1 m/s on an arc through 90 degrees (radius 500 mm:
/// 2 m/s^2 to the centre); whether the dribbler still holds the ball at the end.
fn holds_through_a_turn(pull_mm_s2: f64) -> bool {
    let layout = ball_at_front(Layout::default());
    let mut robot = striker(0.0, 0.0, 0.0);
    robot.kicker = Some(KickerSpec {
        dribbler_pull_mm_s2: pull_mm_s2,
        ..KickerSpec::default()
    });
    robot.accel_limit_mm_s2 = 20_000.0;
    // Spun up gently: 10 rad/s^2 is 1 m/s^2 aside at the ball.
    robot.angular_accel_limit_rad_s2 = 10.0;
    let mut w = World::new(&layout, &[robot], STEP_S).unwrap();
    w.set_ball_command(
        0,
        BallCommand {
            kick: None,
            dribbler_rpm: 5000.0,
        },
    );
    w.advance(0.05);
    assert_eq!(w.ball_holder(), Some(0), "{:?}", w.ball_events());
    // Up to 1 m/s straight ahead.
    for _ in 0..100 {
        w.set_command(0, VelocityCommand::translate(Vector2::new(1000.0, 0.0)));
        w.advance(STEP_S);
    }
    let (speed, omega) = (1000.0, 2.0);
    let mut turned = 0.0;
    while turned < std::f64::consts::FRAC_PI_2 {
        let th = w.robot_state(0).pose.rotation.angle();
        w.set_command(
            0,
            VelocityCommand {
                v_mm_s: Vector2::new(th.cos(), th.sin()) * speed,
                omega_rad_s: omega,
            },
        );
        w.advance(STEP_S);
        turned = w.robot_state(0).pose.rotation.angle();
    }
    w.ball_holder() == Some(0)
}

#[test]
fn the_dribbler_keeps_the_ball_through_a_turn_at_one_metre_a_second_and_loses_it_above_its_pull() {
    // 2 m/s^2 to the centre, plus omega^2 r = 4 * 96.5 mm back at the ball: 2.04 m/s^2.
    assert!(holds_through_a_turn(3000.0));
    assert!(!holds_through_a_turn(1500.0));
}

#[test]
fn the_light_barrier_sees_the_ball_at_the_front_only() {
    let layout = ball_at_front(Layout::default());
    let w = World::new(&layout, &[striker(0.0, 0.0, 0.0)], STEP_S).unwrap();
    assert!(w.light_barrier(0));
    let w = World::new(&layout, &[striker(0.0, 0.0, 1.0)], STEP_S).unwrap();
    assert!(!w.light_barrier(0));
    let mut w = World::new(&layout, &[striker(0.0, 0.0, 0.0)], STEP_S).unwrap();
    w.place_ball(Point2::new(500.0, 0.0), Vector2::zeros());
    assert!(!w.light_barrier(0));
}

#[test]
fn a_kicker_recharges_before_it_fires_again() {
    let layout = ball_at_front(Layout::default());
    let mut w = World::new(&layout, &[striker(0.0, 0.0, 0.0)], STEP_S).unwrap();
    kick(&mut w, 1000.0, 0.0);
    w.advance(STEP_S);
    assert!(!w.kicker_ready(0));
    // The ball put back at the front at once: the armed kick waits for the charge.
    w.place_ball(Point2::new(96.5, 0.0), Vector2::zeros());
    kick(&mut w, 1000.0, 0.0);
    w.advance(0.2);
    assert_eq!(w.ball().unwrap().1.velocity_mm_s.norm(), 0.0);
    w.advance(0.4);
    assert!(w.ball().unwrap().1.velocity_mm_s.norm() > 0.0);
    let kicks = (w.ball_events().iter())
        .filter(|e| matches!(e, BallEvent::Kick { .. }))
        .count();
    assert_eq!(kicks, 2);
}

#[test]
fn ball_kick_scores_on_every_seed_and_its_events_name_the_kick_and_the_goal() {
    for seed in 1..=10 {
        let mut s = scenario("ball_kick.toml");
        s.seed = seed;
        let out = omniloop::run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap();
        let ball = out.summary.ball.as_ref().expect("a ball table");
        assert_eq!(ball.kicks, 1, "seed {seed}: {ball:?}");
        assert_eq!(ball.goals.len(), 1, "seed {seed}: {ball:?}");
        assert_eq!(ball.goals[0].goal, "+x");
        assert_eq!(ball.goals[0].by.as_deref(), Some("robot"));
        assert!(ball.longest_dribble_mm > 200.0 && ball.dribbled_too_far == 0);
        let events = &out.ball.as_ref().unwrap().events;
        let kinds: Vec<&str> = events.iter().filter_map(|e| e["event"].as_str()).collect();
        let kick = kinds.iter().position(|k| *k == "kick").expect("a kick");
        let goal = kinds.iter().position(|k| *k == "goal").expect("a goal");
        assert!(kick < goal, "{kinds:?}");
        assert_eq!(events[goal]["by"], "robot");
    }
}

#[test]
fn the_rollout_scenario_rests_where_the_closed_form_says_and_writes_its_files() {
    let dir = tmp("ball_rollout");
    omniloop([
        "run",
        common::scenario_path("ball_rollout.toml").to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
        "--renderer",
        "cpu",
        "--quiet",
    ]);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let end = summary["ball"]["final_mm"][0].as_f64().unwrap();
    let (d0, _) = BallSpec::default().rest_after_kick(6500.0);
    assert!((end - 96.5 - d0).abs() <= 0.02 * d0, "{end} against {d0}");
    let csv = std::fs::read_to_string(dir.join("ball.csv")).unwrap();
    assert!(csv.starts_with("t_s,x_mm,y_mm,z_mm,vx_mm_s,vy_mm_s,vz_mm_s,held_by\n"));
    let events = std::fs::read_to_string(dir.join("events.jsonl")).unwrap();
    assert!(events.contains("\"event\":\"kick\""), "{events}");
    // 6.5 m/s is the limit, not over it.
    assert_eq!(summary["ball"]["too_fast"], 0);
}

#[test]
fn a_bad_ball_or_kick_is_named_with_its_place_in_the_file() {
    let cases = [
        (
            "center_mm = [-300.0, -250.0]",
            "center_mm = [-300.0, 2000.0]",
            "world.ball.center_mm",
            "outside the floor",
        ),
        (
            "center_mm = [-300.0, -250.0]",
            "center_mm = [-300.0, -380.0]",
            "world.ball.center_mm",
            "inside robot robot",
        ),
        (
            "center_mm = [-300.0, -250.0]",
            "center_mm = [-300.0, -250.0]\nrestitution = nan",
            "world.ball.restitution",
            "within 0 and 1",
        ),
        (
            "speed_mm_s = 5000.0",
            "speed_mm_s = 7000.0",
            "control.script.moves[3].kick.speed_mm_s",
            "6500",
        ),
        (
            "speed_mm_s = 5000.0",
            "speed_mm_s = -1.0",
            "control.script.moves[3].kick.speed_mm_s",
            "within 0",
        ),
        (
            "front_mm = 75.0",
            "front_mm = 95.0",
            "robot.kicker.front_mm",
            "radius",
        ),
    ];
    for (k, (from, to, field, why)) in cases.into_iter().enumerate() {
        let (code, err) = check_variant("ball_kick.toml", &format!("bad_ball_{k}"), from, to);
        assert_eq!(code, Some(2), "{to}: {err}");
        assert!(err.contains(field) && err.contains(why), "{to}: {err}");
        assert!(err.contains("broken.toml:"), "{to}: no location in {err}");
    }
}
