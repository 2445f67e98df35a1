//! A robot's kicker and dribbler (`[robot.kicker]`): a flat front where the body is cut, the
//! dribbler bar across it with its light barrier, and the kicker behind it.
//!
//! **The front.** Small-Size robots cut their round body flat in front, 73-80 mm from the
//! centre, and the ball is played there. The body's footprint is the disc of its radius cut by
//! the line `x = front_mm` of its own frame (x forward); the ball bounces off either.
//!
//! **The light barrier.** It sees the ball when the ball's centre lies within one radius (and a
//! millimetre) of the front, no further aside than half the dribbler's width, with its bottom
//! under the bar (a chipped ball flies over it). It is a sensor of the robot: its software reads
//! it as real robots do.
//!
//! **The dribbler.** Spinning, it holds a ball the barrier sees: the ball then moves with the
//! front, where it touched it. Holding needs the dribbler to give the ball the acceleration the
//! front point has; the front pushes the ball freely, but to pull it back (braking, the
//! centripetal pull of a turn) or aside the dribbler has at most `dribbler_pull_mm_s2`, scaled by
//! its speed up to `full_pull_rpm`. Asked for more, it loses the ball, which goes on as it was
//! going, and cannot catch it again for `regrab_s`.
//!
//! **The kicker.** A kick command stays armed until the barrier sees the ball, then fires once
//! (if charged): the ball leaves at the front point's velocity plus the kick speed along the
//! robot's heading, tilted up by the kick's angle (0: flat; above 0: a chip). The speed is
//! capped at `max_kick_mm_s` (the rules' 6.5 m/s); the kicker then recharges for `recharge_s`.

use nalgebra::{Point2, Vector2};
use omniloop_problem::Problems;
use serde::{Deserialize, Serialize};

/// A robot's kicker and dribbler (`[robot.kicker]`; module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct KickerSpec {
    /// Distance of the flat front from the body's centre.
    pub front_mm: f64,
    /// Width of the dribbler bar across the front (the light barrier's reach aside is half).
    pub dribbler_width_mm: f64,
    /// Height of the dribbler bar's lower edge: a ball whose bottom is higher passes over.
    pub bar_height_mm: f64,
    /// The fastest kick (the rules' limit, 6.5 m/s).
    pub max_kick_mm_s: f64,
    /// Time the kicker needs to charge again after a kick.
    pub recharge_s: f64,
    /// The largest acceleration the spinning dribbler gives the ball toward the robot or aside.
    pub dribbler_pull_mm_s2: f64,
    /// Dribbler speed at which it pulls its full pull (it pulls in proportion below).
    pub full_pull_rpm: f64,
    /// After losing the ball, how long before the dribbler can catch it again.
    pub regrab_s: f64,
}

impl Default for KickerSpec {
    fn default() -> Self {
        Self {
            front_mm: 75.0,
            dribbler_width_mm: 60.0,
            bar_height_mm: 25.0,
            max_kick_mm_s: 6500.0,
            recharge_s: 0.5,
            dribbler_pull_mm_s2: 3000.0,
            full_pull_rpm: 5000.0,
            regrab_s: 0.2,
        }
    }
}

/// What a robot commands its kicker and dribbler.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BallCommand {
    /// A kick to fire as soon as the ball is at the front (cleared when it fires).
    pub kick: Option<Kick>,
    /// Dribbler speed (0: off).
    pub dribbler_rpm: f64,
}

/// A kick: its speed and its angle above the floor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kick {
    /// Speed of the ball off the kicker, mm/s.
    pub speed_mm_s: f64,
    /// Angle above the floor, rad (0: flat; above 0: a chip).
    pub angle_rad: f64,
}

impl Kick {
    /// Checks a kick against a kicker's limit: the problem's message, if any.
    pub fn problem(&self, spec: &KickerSpec) -> Option<String> {
        if !(self.speed_mm_s.is_finite() && self.speed_mm_s >= 0.0) {
            return Some(format!(
                "kick speed {} mm/s must be a finite number >= 0",
                self.speed_mm_s
            ));
        }
        if self.speed_mm_s > spec.max_kick_mm_s {
            return Some(format!(
                "kick speed {} mm/s is over the kicker's limit of {} mm/s",
                self.speed_mm_s, spec.max_kick_mm_s
            ));
        }
        if !(self.angle_rad.is_finite()
            && (0.0..std::f64::consts::FRAC_PI_2).contains(&self.angle_rad))
        {
            return Some(format!(
                "kick angle {} rad must be within 0 (flat) and pi/2",
                self.angle_rad
            ));
        }
        None
    }
}

impl KickerSpec {
    /// Checks every field, under the collector's prefix; `radius_mm` is the body's.
    pub fn check(&self, radius_mm: f64, p: &mut Problems) {
        p.positive("front_mm", self.front_mm);
        if self.front_mm.is_finite() && self.front_mm >= radius_mm {
            p.fail(
                "front_mm",
                format!(
                    "{} must be less than the body's radius {radius_mm}",
                    self.front_mm
                ),
            );
        }
        p.positive("dribbler_width_mm", self.dribbler_width_mm);
        let chord = 2.0
            * (radius_mm * radius_mm - self.front_mm.powi(2))
                .max(0.0)
                .sqrt();
        if self.dribbler_width_mm > chord + 1e-9 {
            p.fail(
                "dribbler_width_mm",
                format!(
                    "{} is wider than the flat front ({chord:.1} mm at front_mm {})",
                    self.dribbler_width_mm, self.front_mm
                ),
            );
        }
        p.positive("bar_height_mm", self.bar_height_mm);
        p.positive("max_kick_mm_s", self.max_kick_mm_s);
        p.non_negative("recharge_s", self.recharge_s);
        p.non_negative("dribbler_pull_mm_s2", self.dribbler_pull_mm_s2);
        p.positive("full_pull_rpm", self.full_pull_rpm);
        p.non_negative("regrab_s", self.regrab_s);
    }

    /// Whether the light barrier sees a ball of radius `r` at `local` (the robot's frame) with
    /// its bottom `bottom_mm` above the floor.
    pub fn barrier(&self, local: Point2<f64>, r: f64, bottom_mm: f64) -> bool {
        let ahead = local.x - self.front_mm;
        (0.0..=r + 1.0).contains(&ahead)
            && local.y.abs() <= 0.5 * self.dribbler_width_mm
            && bottom_mm < self.bar_height_mm
    }

    /// The pull the dribbler gives at `rpm` (mm/s^2).
    pub fn pull_mm_s2(&self, rpm: f64) -> f64 {
        self.dribbler_pull_mm_s2 * (rpm.max(0.0) / self.full_pull_rpm).min(1.0)
    }

    /// Whether the dribbler at `rpm` can give a held ball `accel_local` (the acceleration the
    /// front point has, in the robot's frame): pushing forward is free; pulling back and aside
    /// together must stay within the pull.
    pub fn can_hold(&self, rpm: f64, accel_local: Vector2<f64>) -> bool {
        let back = accel_local.x.min(0.0);
        back.hypot(accel_local.y) <= self.pull_mm_s2(rpm)
    }
}

/// Signed distance from `local` (the robot's frame) to a body of radius `radius_mm` cut flat at
/// `front_mm` (none: a whole disc), and the outward unit normal there (robot frame). Exact
/// inside and off the faces; at the two corners the larger of the two faces' distances.
pub fn body_distance(
    local: Point2<f64>,
    radius_mm: f64,
    front_mm: Option<f64>,
) -> (f64, Vector2<f64>) {
    let r = local.coords.norm();
    let round = r - radius_mm;
    let radial = if r > 1e-12 {
        local.coords / r
    } else {
        Vector2::new(-1.0, 0.0)
    };
    match front_mm {
        Some(f) if local.x - f > round => (local.x - f, Vector2::new(1.0, 0.0)),
        _ => (round, radial),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_barrier_sees_a_ball_touching_the_front_within_the_bar() {
        let k = KickerSpec::default();
        let r = 21.5;
        assert!(k.barrier(Point2::new(75.0 + r, 0.0), r, 0.0));
        assert!(k.barrier(Point2::new(75.0 + r, 29.0), r, 0.0));
        assert!(!k.barrier(Point2::new(75.0 + r, 31.0), r, 0.0));
        assert!(!k.barrier(Point2::new(75.0 + r + 5.0, 0.0), r, 0.0));
        assert!(!k.barrier(Point2::new(75.0 + r, 0.0), r, 30.0));
    }

    #[test]
    fn the_dribbler_pulls_back_and_aside_within_its_pull_and_pushes_freely() {
        let k = KickerSpec::default();
        assert!(k.can_hold(5000.0, Vector2::new(20_000.0, 0.0)));
        assert!(k.can_hold(5000.0, Vector2::new(-2000.0, 2000.0)));
        assert!(!k.can_hold(5000.0, Vector2::new(-2500.0, 2500.0)));
        assert!(!k.can_hold(2500.0, Vector2::new(-2000.0, 0.0)));
        assert!(!k.can_hold(0.0, Vector2::new(-1.0, 0.0)));
    }

    #[test]
    fn a_flat_front_is_a_face_of_the_body() {
        let (d, n) = body_distance(Point2::new(100.0, 0.0), 90.0, Some(75.0));
        assert!((d - 25.0).abs() < 1e-12 && n == Vector2::new(1.0, 0.0));
        let (d, n) = body_distance(Point2::new(-100.0, 0.0), 90.0, Some(75.0));
        assert!((d - 10.0).abs() < 1e-12 && (n.x + 1.0).abs() < 1e-12);
        let (d, _) = body_distance(Point2::new(100.0, 0.0), 90.0, None);
        assert!((d - 10.0).abs() < 1e-12);
    }

    #[test]
    fn kicks_over_the_limit_negative_or_steep_are_refused() {
        let k = KickerSpec::default();
        let kick = |speed_mm_s, deg: f64| Kick {
            speed_mm_s,
            angle_rad: deg.to_radians(),
        };
        assert!(kick(6500.0, 0.0).problem(&k).is_none());
        assert!(kick(6600.0, 0.0).problem(&k).is_some());
        assert!(kick(-1.0, 0.0).problem(&k).is_some());
        assert!(kick(f64::NAN, 0.0).problem(&k).is_some());
        assert!(kick(3000.0, 95.0).problem(&k).is_some());
    }
}
