//! The ball (`[world.ball]`): an orange golf ball on the floor, rolling by the two-phase model
//! the Small-Size teams measured, flying when chipped, bouncing off what it meets.
//!
//! **Rolling.** A kicked ball first slides, its speed falling at `slide_decel_mm_s2`, until the
//! speed is `roll_fraction` times the speed it was kicked at; from there it rolls, slowing at
//! `roll_decel_mm_s2` until it rests. With v0 the kick speed, k the fraction, a_s and a_r the
//! two decelerations, the ball rests after
//!
//! t = (1 - k) v0 / a_s + k v0 / a_r,  d = (1 - k^2) v0^2 / (2 a_s) + k^2 v0^2 / (2 a_r).
//!
//! The defaults are ER-Force's published figures for the league's ball (slide 3.9 m/s^2, roll
//! 0.35 m/s^2, k = 0.69; their simulator's ball model). Each step integrates the model exactly
//! (the switch of phase falls inside a step where it does), so a run matches the closed form to
//! rounding.
//!
//! **Flying.** A chip leaves the floor at `v sin(angle)`; the ball then flies under gravity with
//! no drag (z = vz t - g t^2 / 2, the landing exact within a step). Each landing keeps
//! `bounce_damping_z` of the vertical speed and `bounce_damping_xy` of the horizontal one, and
//! the ball slides again from there; a bounce lower than a millimetre ends the flight (our
//! choices: the league publishes no figure for these two).
//!
//! **Bouncing.** Against a wall, goal, cube or robot whose top is above the ball's bottom, the
//! normal part of the ball's velocity relative to the thing is reversed and scaled by
//! `restitution`; the tangential part is kept. Robots are taken as infinitely heavy: a 46 g
//! ball does not move a robot of some 2.5 kg, so the ball's mass does not enter.

use super::kind::{Kind, Surroundings};
use crate::color::Rgb;
use nalgebra::{Point2, Vector2};
use omniloop_problem::Problems;
use serde::{Deserialize, Serialize};

/// Gravity, mm/s^2.
pub const GRAVITY_MM_S2: f64 = 9810.0;

/// A bounce that would rise less than this (mm) ends a flight.
const LOWEST_BOUNCE_MM: f64 = 1.0;

/// The ball of a scenario (`[world.ball]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BallSpec {
    /// Where it lies at the start (mm).
    pub center_mm: [f64; 2],
    /// Its velocity at the start (mm/s; default at rest). A ball set rolling starts sliding,
    /// like a kicked one.
    pub velocity_mm_s: [f64; 2],
    /// Radius: the league's golf ball is 43 mm across.
    pub radius_mm: f64,
    /// Colour (orange).
    pub rgb: Rgb,
    /// Deceleration while it slides (mm/s^2).
    pub slide_decel_mm_s2: f64,
    /// Deceleration while it rolls (mm/s^2).
    pub roll_decel_mm_s2: f64,
    /// It rolls from this fraction of the speed it was kicked at.
    pub roll_fraction: f64,
    /// Part of the normal speed kept in a bounce off a wall, goal, cube or robot.
    pub restitution: f64,
    /// Part of the vertical speed kept when a flying ball lands.
    pub bounce_damping_z: f64,
    /// Part of the horizontal speed kept when a flying ball lands.
    pub bounce_damping_xy: f64,
    /// The rules' top ball speed (6.5 m/s): faster is an event of the game.
    pub speed_limit_mm_s: f64,
}

impl Default for BallSpec {
    fn default() -> Self {
        Self {
            center_mm: [0.0, 0.0],
            velocity_mm_s: [0.0, 0.0],
            radius_mm: 21.5,
            rgb: Rgb([255, 110, 20]),
            slide_decel_mm_s2: 3900.0,
            roll_decel_mm_s2: 350.0,
            roll_fraction: 0.69,
            restitution: 0.5,
            bounce_damping_z: 0.5,
            bounce_damping_xy: 0.75,
            speed_limit_mm_s: 6500.0,
        }
    }
}

impl BallSpec {
    /// Checks every figure, under the collector's prefix (its place against the world is
    /// [`Kind::check`]'s).
    pub fn check_figures(&self, p: &mut Problems) {
        for (name, v) in [
            ("center_mm", self.center_mm),
            ("velocity_mm_s", self.velocity_mm_s),
        ] {
            p.finite(format!("{name}[0]"), v[0]);
            p.finite(format!("{name}[1]"), v[1]);
        }
        p.positive("radius_mm", self.radius_mm);
        p.positive("slide_decel_mm_s2", self.slide_decel_mm_s2);
        p.positive("roll_decel_mm_s2", self.roll_decel_mm_s2);
        p.positive("speed_limit_mm_s", self.speed_limit_mm_s);
        for (name, v) in [
            ("roll_fraction", self.roll_fraction),
            ("restitution", self.restitution),
            ("bounce_damping_z", self.bounce_damping_z),
            ("bounce_damping_xy", self.bounce_damping_xy),
        ] {
            if !(0.0..=1.0).contains(&v) {
                p.fail(name, format!("must be within 0 and 1 (got {v})"));
            }
        }
    }

    /// Where a flat kick at `v0_mm_s` from rest comes to rest and when: the closed form of the
    /// two-phase model (see the module's documentation), (distance mm, time s).
    pub fn rest_after_kick(&self, v0_mm_s: f64) -> (f64, f64) {
        let (k, a_s, a_r) = (
            self.roll_fraction,
            self.slide_decel_mm_s2,
            self.roll_decel_mm_s2,
        );
        let d = (1.0 - k * k) * v0_mm_s * v0_mm_s / (2.0 * a_s)
            + k * k * v0_mm_s * v0_mm_s / (2.0 * a_r);
        let t = (1.0 - k) * v0_mm_s / a_s + k * v0_mm_s / a_r;
        (d, t)
    }
}

impl Kind for BallSpec {
    /// Its figures; on the floor and clear of every solid at the start (clear of the robots is
    /// the scenario's check, which knows them).
    fn check(&self, _: &[Self], around: &dyn Surroundings, p: &mut Problems) {
        self.check_figures(p);
        let at = Point2::from(self.center_mm);
        if !(at.x.is_finite() && at.y.is_finite() && self.radius_mm > 0.0) {
            return;
        }
        let place = |what: &str| format!("({}, {}) mm is {what}", at.x, at.y);
        if !around.is_floor(at) {
            p.fail("center_mm", place("outside the floor region"));
        }
        let solids = around.solids();
        if solids
            .iter()
            .any(|o| o.shape.distance_mm(at) < self.radius_mm)
        {
            p.fail("center_mm", place("inside a wall, cube, pillar or board"));
        }
    }
}

/// The ball's state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BallState {
    /// Where its centre is over the floor (mm).
    pub position_mm: Point2<f64>,
    /// Height of its centre above the floor (its radius while on the floor).
    pub height_mm: f64,
    /// Horizontal velocity (mm/s).
    pub velocity_mm_s: Vector2<f64>,
    /// Vertical velocity (mm/s; 0 on the floor).
    pub vz_mm_s: f64,
    /// Below this speed it rolls, above it slides (mm/s): the roll fraction of the speed it was
    /// last set going at.
    pub roll_below_mm_s: f64,
}

impl BallState {
    /// A ball at `position_mm` on the floor, going at `velocity_mm_s` (sliding).
    pub fn on_floor(
        spec: &BallSpec,
        position_mm: Point2<f64>,
        velocity_mm_s: Vector2<f64>,
    ) -> Self {
        Self {
            position_mm,
            height_mm: spec.radius_mm,
            velocity_mm_s,
            vz_mm_s: 0.0,
            roll_below_mm_s: spec.roll_fraction * velocity_mm_s.norm(),
        }
    }

    /// Whether it is off the floor.
    pub fn flying(&self, spec: &BallSpec) -> bool {
        self.vz_mm_s != 0.0 || self.height_mm > spec.radius_mm
    }

    /// Height of its bottom above the floor.
    pub fn bottom_mm(&self, spec: &BallSpec) -> f64 {
        self.height_mm - spec.radius_mm
    }

    /// Sets it going at `velocity_mm_s` horizontally and `vz_mm_s` up (a kick or a chip): it
    /// slides from there.
    pub fn launch(&mut self, spec: &BallSpec, velocity_mm_s: Vector2<f64>, vz_mm_s: f64) {
        self.velocity_mm_s = velocity_mm_s;
        self.vz_mm_s = vz_mm_s;
        self.roll_below_mm_s = spec.roll_fraction * velocity_mm_s.norm();
    }

    /// Moves it on `dt_s` with nothing in its way: flying under gravity, or sliding and
    /// rolling on the floor.
    pub fn advance(&mut self, spec: &BallSpec, dt_s: f64) {
        if self.flying(spec) {
            self.fly(spec, dt_s);
        } else {
            self.roll(spec, dt_s);
        }
    }

    /// Flight under gravity for `dt_s`, landing (and bouncing) where it meets the floor.
    fn fly(&mut self, spec: &BallSpec, dt_s: f64) {
        let g = GRAVITY_MM_S2;
        let z0 = self.height_mm - spec.radius_mm;
        let z1 = z0 + self.vz_mm_s * dt_s - 0.5 * g * dt_s * dt_s;
        if z1 > 0.0 {
            self.position_mm += self.velocity_mm_s * dt_s;
            self.height_mm = z1 + spec.radius_mm;
            self.vz_mm_s -= g * dt_s;
            return;
        }
        // Lands within the step: the later root of z0 + vz t - g t^2 / 2 = 0.
        let vz = self.vz_mm_s;
        let t_land = ((vz + (vz * vz + 2.0 * g * z0.max(0.0)).sqrt()) / g).clamp(0.0, dt_s);
        self.position_mm += self.velocity_mm_s * t_land;
        let down = vz - g * t_land;
        self.height_mm = spec.radius_mm;
        self.velocity_mm_s *= spec.bounce_damping_xy;
        self.roll_below_mm_s = spec.roll_fraction * self.velocity_mm_s.norm();
        let up = -down * spec.bounce_damping_z;
        self.vz_mm_s = if up * up / (2.0 * g) < LOWEST_BOUNCE_MM {
            0.0
        } else {
            up
        };
        self.advance(spec, dt_s - t_land);
    }

    /// Sliding then rolling on the floor for `dt_s`, exactly: the phase switch and the stop
    /// fall where they do inside the step.
    fn roll(&mut self, spec: &BallSpec, dt_s: f64) {
        let mut left = dt_s;
        let mut speed = self.velocity_mm_s.norm();
        if speed == 0.0 {
            return;
        }
        let dir = self.velocity_mm_s / speed;
        let mut travelled = 0.0;
        while left > 0.0 && speed > 0.0 {
            let sliding = speed > self.roll_below_mm_s;
            let (a, floor) = if sliding {
                (spec.slide_decel_mm_s2, self.roll_below_mm_s)
            } else {
                (spec.roll_decel_mm_s2, 0.0)
            };
            let t = ((speed - floor) / a).min(left);
            travelled += speed * t - 0.5 * a * t * t;
            speed = if t * a >= speed - floor {
                floor
            } else {
                speed - a * t
            };
            left -= t;
        }
        self.position_mm += dir * travelled;
        self.velocity_mm_s = dir * speed;
    }

    /// Bounces off a surface with outward unit normal `n` that it overlaps by `depth_mm`, the
    /// surface moving at `surface_mm_s` there: pushed out, and the normal part of its relative
    /// velocity reversed and scaled by the restitution when it moves into the surface.
    /// Whether it bounced.
    pub fn bounce(
        &mut self,
        spec: &BallSpec,
        n: Vector2<f64>,
        depth_mm: f64,
        surface_mm_s: Vector2<f64>,
    ) -> bool {
        self.position_mm += n * depth_mm.max(0.0);
        let rel = self.velocity_mm_s - surface_mm_s;
        let into = rel.dot(&n);
        if into >= 0.0 {
            return false;
        }
        self.velocity_mm_s = surface_mm_s + rel - n * ((1.0 + spec.restitution) * into);
        // A bounce sets it sliding at its new speed only when the speed rose (a push).
        let speed = self.velocity_mm_s.norm();
        if speed > rel.norm() {
            self.roll_below_mm_s = spec.roll_fraction * speed;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f64 = 0.002;

    fn run_to_rest(spec: &BallSpec, v0: f64) -> (f64, f64) {
        let mut b = BallState::on_floor(spec, Point2::origin(), Vector2::new(v0, 0.0));
        let mut t = 0.0;
        while b.velocity_mm_s.norm() > 0.0 {
            b.advance(spec, DT);
            t += DT;
        }
        (b.position_mm.x, t)
    }

    #[test]
    fn a_flat_kick_rests_where_and_when_the_two_phase_model_says() {
        let spec = BallSpec::default();
        for v0 in [1000.0, 3000.0, 6500.0] {
            let (d, t) = run_to_rest(&spec, v0);
            let (d0, t0) = spec.rest_after_kick(v0);
            assert!((d - d0).abs() <= 0.02 * d0, "{v0}: {d} mm against {d0}");
            // The run stops within the step that holds the closed form's time.
            assert!(
                (t - t0).abs() <= DT.max(0.02 * t0),
                "{v0}: {t} s against {t0}"
            );
            // Exact integration: far inside the 2 % asked for.
            assert!((d - d0).abs() < 1e-6 * d0, "{v0}: {d} against {d0}");
        }
    }

    #[test]
    fn the_phase_switches_at_the_roll_fraction_of_the_kick_speed() {
        let spec = BallSpec::default();
        let mut b = BallState::on_floor(&spec, Point2::origin(), Vector2::new(3000.0, 0.0));
        // Sliding: 3.9 m/s^2 for 0.1 s.
        b.advance(&spec, 0.1);
        assert!((b.velocity_mm_s.x - (3000.0 - 390.0)).abs() < 1e-9);
        // The slide ends at 0.69 * 3000 = 2070 mm/s, after (3000 - 2070) / 3900 s.
        let t_slide = 930.0 / 3900.0;
        let mut b = BallState::on_floor(&spec, Point2::origin(), Vector2::new(3000.0, 0.0));
        b.advance(&spec, t_slide + 1.0);
        assert!((b.velocity_mm_s.x - (2070.0 - 350.0)).abs() < 1e-9);
    }

    #[test]
    fn a_chip_lands_where_the_ballistic_flight_does() {
        let spec = BallSpec::default();
        for (speed, deg) in [(3000.0, 45.0), (5000.0, 30.0), (6500.0, 60.0)] {
            let a = f64::to_radians(deg);
            let mut b = BallState::on_floor(&spec, Point2::origin(), Vector2::zeros());
            b.launch(&spec, Vector2::new(speed * a.cos(), 0.0), speed * a.sin());
            let (vx, vz) = (speed * a.cos(), speed * a.sin());
            let landing = vx * 2.0 * vz / GRAVITY_MM_S2;
            let mut x_land = None;
            for _ in 0..5000 {
                let vz_before = b.vz_mm_s;
                b.advance(&spec, DT);
                // The first landing: the vertical speed turned from down to up (or to rest).
                if vz_before < 0.0 && b.vz_mm_s >= 0.0 {
                    // Step back the part of the step flown after landing.
                    x_land = Some(b.position_mm.x);
                    break;
                }
            }
            let x = x_land.expect("it lands");
            assert!(
                (x - landing).abs() <= 0.02 * landing,
                "{speed} at {deg}: {x} against {landing}"
            );
            // After the bounce it keeps the damping's part of its horizontal speed.
            assert!((b.velocity_mm_s.x - vx * spec.bounce_damping_xy).abs() < 1e-6 * vx);
        }
    }

    #[test]
    fn a_bounce_keeps_the_restitution_of_the_normal_speed_and_the_tangential_speed() {
        let spec = BallSpec {
            restitution: 0.6,
            ..BallSpec::default()
        };
        let mut b = BallState::on_floor(&spec, Point2::origin(), Vector2::new(2000.0, 500.0));
        // A wall facing -x.
        assert!(b.bounce(&spec, Vector2::new(-1.0, 0.0), 2.0, Vector2::zeros()));
        assert!((b.velocity_mm_s.x + 1200.0).abs() < 1e-9);
        assert!((b.velocity_mm_s.y - 500.0).abs() < 1e-9);
        assert!((b.position_mm.x + 2.0).abs() < 1e-12);
        // Moving away already: no bounce.
        assert!(!b.bounce(&spec, Vector2::new(-1.0, 0.0), 0.0, Vector2::zeros()));
        // A surface moving into the ball pushes it: relative speed reversed.
        let mut b = BallState::on_floor(&spec, Point2::origin(), Vector2::zeros());
        assert!(b.bounce(
            &spec,
            Vector2::new(1.0, 0.0),
            0.0,
            Vector2::new(1000.0, 0.0)
        ));
        assert!((b.velocity_mm_s.x - 1600.0).abs() < 1e-9);
        assert!((b.roll_below_mm_s - 0.69 * 1600.0).abs() < 1e-9);
    }

    #[test]
    fn bad_values_are_named() {
        let spec = BallSpec {
            radius_mm: -1.0,
            restitution: 1.5,
            center_mm: [f64::NAN, 0.0],
            ..BallSpec::default()
        };
        let mut p = Problems::under("world.ball");
        spec.check_figures(&mut p);
        let text = format!("{p:?}");
        for f in ["radius_mm", "restitution", "center_mm"] {
            assert!(text.contains(f), "{f} in {text}");
        }
    }
}
