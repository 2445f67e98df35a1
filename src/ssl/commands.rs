//! A team's robot command off the wire, judged: how the robot is to move (held until the next
//! command or the timeout), its kick and its dribbler, and what was wrong with it as the
//! protocol's `SimulatorError`s. Protocol units (m/s, degrees for the kick angle) become
//! omniloop's (mm/s, rad) here.

use super::wire::sim::{MoveCommand, MoveWheelVelocity, RobotCommand, SimulatorError};
use nalgebra::{Matrix4x3, Vector2, Vector4};

/// A velocity command more than this many times a robot's top speed is refused (a real
/// robot saturates at its top speed; such a number is a bug in the sender).
const HUGE_FACTOR: f64 = 10.0;
/// The fastest turn a robot is commanded, rad/s (faster commands are cut to it).
pub const MAX_TURN_RAD_S: f64 = 4.0 * std::f64::consts::PI;

/// How a robot was last told to move.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Drive {
    /// Stand still (no command yet, a refused one, or the timeout).
    #[default]
    Stop,
    /// A velocity in the robot's frame (x forward, y left), mm/s and rad/s.
    Local(Vector2<f64>, f64),
    /// A velocity in the field's frame, mm/s and rad/s: turned into the robot's frame each
    /// cycle, with the robot's heading then.
    Global(Vector2<f64>, f64),
}

/// What a robot can do, for judging its commands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Abilities {
    /// Its top speed, mm/s.
    pub max_speed_mm_s: f64,
    /// Its kicker's limit, mm/s (none: no kicker).
    pub max_kick_mm_s: Option<f64>,
    /// Its wheels' angles, rad clockwise from forward: front right, back right, back left,
    /// front left.
    pub wheel_angles_rad: [f64; 4],
    /// Its wheels' distance from its centre, mm.
    pub wheel_radius_mm: f64,
}

/// A command, judged.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Judged {
    /// The new drive (none: the command did not say how to move; the last holds).
    pub drive: Option<Drive>,
    /// A kick to arm: speed mm/s and angle above the floor, rad.
    pub kick: Option<(f64, f64)>,
    /// The dribbler's new speed, rpm.
    pub dribbler_rpm: Option<f64>,
    /// What was wrong.
    pub errors: Vec<SimulatorError>,
}

/// An error with its code and message.
pub fn error(code: &str, message: String) -> SimulatorError {
    SimulatorError {
        code: Some(code.to_string()),
        message: Some(message),
    }
}

/// Judges `c`, a command to robot `who` (e.g. `blue 3`) that can do `a`.
pub fn judge(c: &RobotCommand, who: &str, a: &Abilities) -> Judged {
    let mut j = Judged::default();
    if let Some(m) = c.move_command.as_ref().and_then(|m| m.command.as_ref()) {
        let (v, omega, global) = match m {
            MoveCommand::LocalVelocity(l) => (
                Vector2::new(f64::from(l.forward), f64::from(l.left)) * 1000.0,
                f64::from(l.angular),
                false,
            ),
            MoveCommand::GlobalVelocity(g) => (
                Vector2::new(f64::from(g.x), f64::from(g.y)) * 1000.0,
                f64::from(g.angular),
                true,
            ),
            MoveCommand::WheelVelocity(w) => {
                let (v, omega) = wheels_to_body(w, a);
                (v, omega, false)
            }
        };
        j.drive = Some(match velocity_problem(v, omega, a) {
            Some(why) => {
                j.errors
                    .push(error("INVALID_VELOCITY", format!("{who}: {why}; it stops")));
                Drive::Stop
            }
            None => {
                let omega = omega.clamp(-MAX_TURN_RAD_S, MAX_TURN_RAD_S);
                if global {
                    Drive::Global(v, omega)
                } else {
                    Drive::Local(v, omega)
                }
            }
        });
    }
    judge_kick(c, who, a, &mut j);
    if let Some(rpm) = c.dribbler_speed.map(f64::from) {
        if rpm.is_finite() {
            j.dribbler_rpm = Some(rpm.abs());
        } else {
            j.errors.push(error(
                "INVALID_DRIBBLER",
                format!("{who}: dribbler speed {rpm} rpm is not a number; it stops"),
            ));
            j.dribbler_rpm = Some(0.0);
        }
    }
    j
}

/// Why a velocity is refused: not finite, or far over what the robot can do.
fn velocity_problem(v: Vector2<f64>, omega: f64, a: &Abilities) -> Option<String> {
    if !(v.x.is_finite() && v.y.is_finite() && omega.is_finite()) {
        return Some(format!(
            "velocity ({}, {}) mm/s, {omega} rad/s is not a number",
            v.x, v.y
        ));
    }
    let huge = HUGE_FACTOR * a.max_speed_mm_s;
    if v.norm() > huge {
        return Some(format!(
            "speed {:.0} mm/s is over {huge:.0} mm/s, {HUGE_FACTOR} times its top speed",
            v.norm()
        ));
    }
    None
}

/// The kick, checked against the kicker: none without one, cut to its limit.
fn judge_kick(c: &RobotCommand, who: &str, a: &Abilities, j: &mut Judged) {
    let Some(speed) = c.kick_speed.map(|s| f64::from(s) * 1000.0) else {
        return;
    };
    let angle_deg = f64::from(c.kick_angle.unwrap_or(0.0));
    if !(speed.is_finite() && speed >= 0.0 && angle_deg.is_finite()) {
        j.errors.push(error(
            "INVALID_KICK",
            format!("{who}: kick of {speed} mm/s at {angle_deg} degrees is not a kick"),
        ));
        return;
    }
    if speed == 0.0 {
        j.kick = Some((0.0, 0.0));
        return;
    }
    let Some(max) = a.max_kick_mm_s else {
        j.errors.push(error(
            "NO_KICKER",
            format!("{who} has no kicker ([robot.kicker]): the kick is ignored"),
        ));
        return;
    };
    if !(0.0..90.0).contains(&angle_deg) {
        j.errors.push(error(
            "INVALID_KICK",
            format!("{who}: kick angle {angle_deg} degrees is not within 0 and 90"),
        ));
        return;
    }
    if speed > max {
        j.errors.push(error(
            "KICK_OVER_LIMIT",
            format!(
                "{who}: kick speed {:.2} m/s is over the kicker's {:.2} m/s: kicked at that",
                speed / 1000.0,
                max / 1000.0
            ),
        ));
    }
    j.kick = Some((speed.min(max), angle_deg.to_radians()));
}

/// The body velocity (mm/s, rad/s) that gives these rim speeds, least squares over the four
/// wheels. Wheel k stands at angle `-θ_k` (counter-clockwise) from forward, `R` from the
/// centre, and rolls along `t_k = (-sin(-θ_k), cos(-θ_k))`: its rim speed is
/// `s_k = t_k · v + R ω` (a positive speed on all four turns the robot counter-clockwise).
pub fn wheels_to_body(w: &MoveWheelVelocity, a: &Abilities) -> (Vector2<f64>, f64) {
    let rims = [w.front_right, w.back_right, w.back_left, w.front_left].map(f64::from);
    let s = Vector4::from(rims) * 1000.0;
    let m = wheel_matrix(a);
    let normal = m.transpose() * m;
    match normal.try_inverse() {
        Some(inv) => {
            let x = inv * m.transpose() * s;
            (Vector2::new(x[0], x[1]), x[2] / a.wheel_radius_mm)
        }
        None => (Vector2::new(f64::NAN, f64::NAN), f64::NAN),
    }
}

/// The rim speeds of a body velocity (the inverse of [`wheels_to_body`]), mm/s.
pub fn body_to_wheels(v: Vector2<f64>, omega: f64, a: &Abilities) -> [f64; 4] {
    let s = wheel_matrix(a) * nalgebra::Vector3::new(v.x, v.y, omega * a.wheel_radius_mm);
    [s[0], s[1], s[2], s[3]]
}

/// Rows `(t_x, t_y, 1)` of each wheel: rim speed = row · (v_x, v_y, R ω).
fn wheel_matrix(a: &Abilities) -> Matrix4x3<f64> {
    let mut m = Matrix4x3::zeros();
    // Wheel k's position is at -θ_k counter-clockwise from forward.
    for (k, theta) in a.wheel_angles_rad.iter().enumerate() {
        let phi = -theta;
        m[(k, 0)] = -phi.sin();
        m[(k, 1)] = phi.cos();
        m[(k, 2)] = 1.0;
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ssl::wire::sim::{MoveLocalVelocity, RobotMoveCommand};

    fn abilities() -> Abilities {
        Abilities {
            max_speed_mm_s: 3000.0,
            max_kick_mm_s: Some(6500.0),
            wheel_angles_rad: [60.0f64, 135.0, 225.0, 300.0].map(f64::to_radians),
            wheel_radius_mm: 80.0,
        }
    }

    fn local(forward: f32, left: f32, angular: f32) -> RobotCommand {
        RobotCommand {
            id: 0,
            move_command: Some(RobotMoveCommand {
                command: Some(MoveCommand::LocalVelocity(MoveLocalVelocity {
                    forward,
                    left,
                    angular,
                })),
            }),
            kick_speed: None,
            kick_angle: None,
            dribbler_speed: None,
        }
    }

    #[test]
    fn wheel_speeds_of_a_body_velocity_give_it_back() {
        let a = abilities();
        let (v, omega) = (Vector2::new(700.0, -300.0), 1.5);
        let s = body_to_wheels(v, omega, &a);
        let w = MoveWheelVelocity {
            front_right: (s[0] / 1000.0) as f32,
            back_right: (s[1] / 1000.0) as f32,
            back_left: (s[2] / 1000.0) as f32,
            front_left: (s[3] / 1000.0) as f32,
        };
        let (v2, omega2) = wheels_to_body(&w, &a);
        assert!((v2 - v).norm() < 0.01, "{v2:?}");
        assert!((omega2 - omega).abs() < 1e-4, "{omega2}");
        // Straight ahead: the front wheels turn opposite ways, the right one forward (a
        // positive speed on every wheel turns the robot counter-clockwise).
        let ahead = body_to_wheels(Vector2::new(1000.0, 0.0), 0.0, &a);
        assert!(
            ahead[0] > 0.0 && (ahead[0] + ahead[3]).abs() < 1e-9,
            "{ahead:?}"
        );
        let spin = body_to_wheels(Vector2::zeros(), 1.0, &a);
        assert!(
            spin.iter().all(|s| (s - a.wheel_radius_mm).abs() < 1e-9),
            "{spin:?}"
        );
    }

    #[test]
    fn a_local_velocity_in_metres_becomes_millimetres() {
        let j = judge(&local(1.0, -0.5, 2.0), "blue 0", &abilities());
        assert_eq!(
            j.drive,
            Some(Drive::Local(Vector2::new(1000.0, -500.0), 2.0))
        );
        assert!(j.errors.is_empty());
    }

    #[test]
    fn nan_and_huge_velocities_stop_the_robot_with_an_error() {
        for c in [
            local(f32::NAN, 0.0, 0.0),
            local(1e6, 0.0, 0.0),
            local(0.0, 0.0, f32::INFINITY),
        ] {
            let j = judge(&c, "blue 0", &abilities());
            assert_eq!(j.drive, Some(Drive::Stop));
            assert_eq!(j.errors[0].code.as_deref(), Some("INVALID_VELOCITY"));
        }
    }

    #[test]
    fn kicks_are_cut_to_the_limit_and_refused_without_a_kicker() {
        let mut c = local(0.0, 0.0, 0.0);
        c.kick_speed = Some(10.0);
        c.kick_angle = Some(45.0);
        let j = judge(&c, "yellow 2", &abilities());
        assert_eq!(j.errors[0].code.as_deref(), Some("KICK_OVER_LIMIT"));
        let (speed, angle) = j.kick.unwrap();
        assert_eq!(speed, 6500.0);
        assert!((angle - std::f64::consts::FRAC_PI_4).abs() < 1e-9);
        let none = Abilities {
            max_kick_mm_s: None,
            ..abilities()
        };
        let j = judge(&c, "yellow 2", &none);
        assert_eq!(j.kick, None);
        assert_eq!(j.errors[0].code.as_deref(), Some("NO_KICKER"));
    }
}
