//! Random wandering on a map (E4, Spacek and Burbridge, Sect. 2.1): "The controller drives the
//! robot forwards, checking the map until it is at a pillar or a wall. It then randomly turns
//! either left or right."
//!
//! The robot judges "at a pillar or a wall" on its own pose estimate and its map: the way ahead
//! is blocked when the straight path the robot would sweep before it could stop from top speed
//! (`v^2 / (2 alpha)` plus two control periods) brings its body within `clearance_mm` of an
//! obstacle and nearer than it is now (so a robot already close can drive away). It then stops
//! and turns in place, left or right at random, until the way ahead is clear, and on by a
//! random extra angle (ours; see [`WanderConfig`]). The turns come from the software's
//! own seeded generator: a run repeats exactly.

use crate::RobotError;
use crate::boundary::BodyCommand;
use crate::config::{ControlSpec, RobotConfig, WorldMap};
use crate::controller::{
    ControlTable, Controller, ControllerEntry, Situation, check_table, settings,
};
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_problem::{Problem, Problems};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use serde::{Deserialize, Serialize};

/// The registry's entry.
pub const ENTRY: ControllerEntry = ControllerEntry {
    name: "wander",
    summary: "random wandering on the map: forward until an obstacle is near, then a random turn \
              (E4, Spacek and Burbridge, Sect. 2.1)",
    tables: &[ControlTable {
        name: "wander",
        check: check_wander,
    }],
    needs_goal: false,
    stages: &[],
    check_use: |c| {
        if c.map.segments.is_empty() && c.map.boxes.is_empty() {
            return vec![Problem::new(
                "control.kind",
                "\"wander\" drives on a map of the world's walls and pillars: the world has no walls",
            )];
        }
        Vec::new()
    },
    build: |c| Ok(Box::new(Wander::new(c)?)),
};

/// How the wandering controller drives (`[control.wander]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WanderConfig {
    /// Gap the robot keeps between its body and the map's obstacles, mm (room for the error
    /// of its estimate).
    pub clearance_mm: f64,
    /// Rate of the turns, deg/s.
    pub turn_rate_deg_s: f64,
    /// Once the way ahead is clear the robot turns on by a random angle up to this, degrees
    /// (ours: without it a robot that stops turning at the first clear heading skims along
    /// walls).
    pub max_extra_turn_deg: f64,
}

impl Default for WanderConfig {
    fn default() -> Self {
        Self {
            clearance_mm: 200.0,
            turn_rate_deg_s: 90.0,
            max_extra_turn_deg: 60.0,
        }
    }
}

/// Parses and checks `[control.wander]`.
fn check_wander(spec: &ControlSpec) -> Vec<Problem> {
    check_table(spec, "wander", |w: &WanderConfig, p: &mut Problems| {
        p.positive("clearance_mm", w.clearance_mm);
        p.positive("turn_rate_deg_s", w.turn_rate_deg_s);
        p.non_negative("max_extra_turn_deg", w.max_extra_turn_deg);
    })
}

/// Step along the path ahead at which the map is checked, mm.
const STEP_MM: f64 = 10.0;

#[derive(Debug, Clone, Copy, PartialEq)]
enum State {
    Forward,
    /// Turning in place: direction (+1 left), and the extra angle still to turn once clear.
    Turn {
        dir: f64,
        extra_rad: f64,
    },
}

/// The wandering controller.
pub struct Wander {
    config: WanderConfig,
    map: WorldMap,
    radius_mm: f64,
    speed_mm_s: f64,
    look_ahead_mm: f64,
    period_s: f64,
    rng: StdRng,
    state: State,
}

impl Wander {
    /// The controller of `config`'s robot, on its map.
    pub fn new(config: &RobotConfig) -> Result<Self, RobotError> {
        let w: WanderConfig = settings(config, "wander")?;
        for (name, v) in [
            ("control.wander.clearance_mm", w.clearance_mm),
            ("control.wander.turn_rate_deg_s", w.turn_rate_deg_s),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(RobotError::Field(Problem::new(
                    name,
                    format!("must be positive (got {v})"),
                )));
            }
        }
        if config.map.landmarks.is_empty()
            && config.map.segments.is_empty()
            && config.map.boxes.is_empty()
        {
            return Err(RobotError::Field(Problem::new(
                "control.kind",
                "\"wander\" needs a map: the world has no walls or pillars",
            )));
        }
        let b = &config.body;
        let v = b.max_speed_mm_s;
        Ok(Self {
            config: w,
            map: config.map.clone(),
            radius_mm: b.radius_mm,
            speed_mm_s: v,
            look_ahead_mm: v * v / (2.0 * b.accel_limit_mm_s2) + 2.0 * v * config.control_period_s,
            period_s: config.control_period_s,
            rng: StdRng::seed_from_u64(config.seed ^ 0x5741_4e44_4552),
            state: State::Forward,
        })
    }

    /// Distance from a point to the nearest obstacle's surface, mm.
    fn gap_mm(&self, p: Point2<f64>) -> f64 {
        let pillars = self
            .map
            .landmarks
            .iter()
            .map(|l| (p - l.centre_mm).norm() - l.radius_mm);
        let segments = self.map.segments.iter().chain(&self.map.boxes).map(|s| {
            let ab = s.to_mm - s.from_mm;
            let t = ((p - s.from_mm).dot(&ab) / ab.norm_squared().max(1e-9)).clamp(0.0, 1.0);
            (p - (s.from_mm + ab * t)).norm() - s.half_thickness_mm
        });
        pillars.chain(segments).fold(f64::INFINITY, f64::min) - self.radius_mm
    }

    /// Whether driving ahead from `pose` would bring the body within the clearance of an
    /// obstacle, and nearer than it is now.
    fn blocked(&self, pose: &Isometry2<f64>) -> bool {
        let here = Point2::from(pose.translation.vector);
        let ahead = pose.rotation * Vector2::x();
        let now = self.gap_mm(here);
        let reach = self.look_ahead_mm + self.config.clearance_mm;
        let steps = (reach / STEP_MM).ceil() as usize;
        (1..=steps).any(|k| {
            let g = self.gap_mm(here + ahead * (k as f64 * STEP_MM));
            g < self.config.clearance_mm && g < now
        })
    }

    fn turn(&self, dir: f64) -> BodyCommand {
        BodyCommand::turn(dir * self.config.turn_rate_deg_s.to_radians())
    }
}

impl Controller for Wander {
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand {
        let Some(pose) = s.pose else {
            return BodyCommand::STOP;
        };
        let blocked = self.blocked(&pose);
        self.state = match self.state {
            State::Forward if blocked => State::Turn {
                dir: if self.rng.random_bool(0.5) { 1.0 } else { -1.0 },
                extra_rad: self.rng.random::<f64>() * self.config.max_extra_turn_deg.to_radians(),
            },
            State::Turn { dir, extra_rad } if !blocked => {
                if extra_rad > 0.0 {
                    State::Turn {
                        dir,
                        extra_rad: extra_rad
                            - self.config.turn_rate_deg_s.to_radians() * self.period_s,
                    }
                } else {
                    State::Forward
                }
            }
            other => other,
        };
        match self.state {
            State::Forward => BodyCommand::forward(self.speed_mm_s),
            State::Turn { dir, .. } => self.turn(dir),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{BodySpec, MapSegment};
    use crate::percept::Percepts;

    fn config() -> RobotConfig {
        let seg = |a: [f64; 2], b: [f64; 2]| MapSegment {
            from_mm: Point2::from(a),
            to_mm: Point2::from(b),
            half_thickness_mm: 50.0,
        };
        RobotConfig {
            name: "robot".to_string(),
            start: Isometry2::identity(),
            body: BodySpec {
                radius_mm: 150.0,
                max_speed_mm_s: 300.0,
                accel_limit_mm_s2: 1000.0,
                angular_accel_limit_rad_s2: 8.0,
                kicker: None,
            },
            control_period_s: 0.05,
            map: WorldMap {
                landmarks: Vec::new(),
                segments: vec![seg([1000.0, -1000.0], [1000.0, 1000.0])],
                ..WorldMap::default()
            },
            seed: 3,
            ..RobotConfig::for_tests()
        }
    }

    fn situation(pose: Isometry2<f64>) -> Situation<'static> {
        static NOTHING: Percepts = Percepts::new();
        Situation {
            percepts: &NOTHING,
            target_body_mm: None,
            target_mm: None,
            velocity_body_mm_s: Vector2::zeros(),
            pose: Some(pose),
            odometry_pose: Isometry2::identity(),
            t_s: 0.0,
            actuators: &[],
        }
    }

    #[test]
    fn drives_on_until_the_wall_then_turns_until_clear() {
        let mut w = Wander::new(&config()).unwrap();
        // Far from the wall at x = 950 (its face): forward at top speed.
        let c = w.decide(&situation(Isometry2::new(Vector2::new(0.0, 0.0), 0.0)));
        assert_eq!(c.v_mm_s, Vector2::new(300.0, 0.0));
        // Body 250 mm from the wall's face, facing it: within clearance + stopping path.
        let near = Isometry2::new(Vector2::new(550.0, 0.0), 0.0);
        let c = w.decide(&situation(near));
        assert_eq!(c.v_mm_s, Vector2::zeros());
        assert!(c.omega_rad_s.abs() > 1.0);
        // Facing away, it goes on turning by its extra angle, then drives away.
        let away = Isometry2::new(Vector2::new(550.0, 0.0), std::f64::consts::PI);
        let mut forward = false;
        for _ in 0..40 {
            let c = w.decide(&situation(away));
            if c.v_mm_s.x > 0.0 {
                forward = true;
                break;
            }
        }
        assert!(forward);
    }

    #[test]
    fn the_turns_repeat_with_the_seed() {
        let dirs = |seed: u64| -> Vec<f64> {
            let mut c = config();
            c.seed = seed;
            let mut w = Wander::new(&c).unwrap();
            (0..8)
                .map(|_| {
                    w.state = State::Forward;
                    w.decide(&situation(Isometry2::new(Vector2::new(600.0, 0.0), 0.0)))
                        .omega_rad_s
                })
                .collect()
        };
        assert_eq!(dirs(3), dirs(3));
        assert!(dirs(3).iter().any(|&d| d > 0.0) && dirs(3).iter().any(|&d| d < 0.0));
    }
}
