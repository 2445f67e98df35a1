//! Scripted moves on dead reckoning: straight runs and turns on the spot, each ending at rest
//! (`[control.script]`; E6's square of Fig. 8 and the tests of Fig. 10), and the kicker's and
//! dribbler's commands, so a scenario can play the ball before any robot can see it.

use crate::boundary::{ActuatorCommand, BodyCommand};
use crate::config::RobotConfig;
use crate::controller::{ControlTable, Controller, ControllerEntry, Situation, parses, settings};
use omniloop_control::wrap_pi;
use omniloop_problem::{Problem, Problems};
use serde::{Deserialize, Serialize};

/// The registry's entry.
pub const ENTRY: ControllerEntry = ControllerEntry {
    name: "script",
    summary: "drive a list of moves (straight runs, turns on the spot) on dead reckoning \
              ([control.script])",
    tables: &[ControlTable {
        name: "script",
        check: |spec| parses::<ScriptConfig>(spec, "script"),
    }],
    needs_goal: false,
    stages: &[],
    check_use: check_kicks,
    build: |c| {
        Ok(Box::new(Script {
            script: settings(c, "script")?,
            accel_mm_s2: c.body.accel_limit_mm_s2,
            angular_accel_rad_s2: c.body.angular_accel_limit_rad_s2,
            period_s: c.control_period_s,
            index: 0,
            phase: None,
            actuators: Vec::new(),
        }))
    },
};

/// Each kick of the script against the robot's kicker: it needs one, and a speed within its
/// limit (not negative), an angle within 0 and 90 degrees.
fn check_kicks(config: &RobotConfig) -> Vec<Problem> {
    let Ok(script) = config.control.table::<ScriptConfig>("script") else {
        return Vec::new();
    };
    let mut p = Problems::under("control.script");
    for (i, m) in script.moves.iter().enumerate() {
        let at = format!("moves[{i}]");
        match (*m, config.body.kicker.map(|k| k.max_kick_mm_s)) {
            (Move::Kick(_), None) => p.fail(at, "a kick needs a kicker: add [robot.kicker]"),
            (Move::Kick(k), Some(limit)) => {
                if !(k.speed_mm_s.is_finite() && (0.0..=limit).contains(&k.speed_mm_s)) {
                    let why = format!("must be within 0 and the kicker's {limit} mm/s");
                    p.fail(
                        format!("{at}.kick.speed_mm_s"),
                        format!("{why} (got {})", k.speed_mm_s),
                    );
                }
                if !(k.angle_deg.is_finite() && (0.0..90.0).contains(&k.angle_deg)) {
                    let why = format!("must be within 0 and 90 (got {})", k.angle_deg);
                    p.fail(format!("{at}.kick.angle_deg"), why);
                }
            }
            (Move::DribbleRpm(rpm), _) if !(rpm.is_finite() && rpm >= 0.0) => p.fail(
                format!("{at}.dribble_rpm"),
                format!("must be >= 0 (got {rpm})"),
            ),
            _ => {}
        }
    }
    p.into_vec()
}

/// One move of a script.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Move {
    /// Straight ahead by this much (negative: back), mm: `{ forward_mm = 914.4 }`.
    ForwardMm(f64),
    /// Turn on the spot by this much (counter-clockwise positive), degrees:
    /// `{ turn_deg = -90.0 }`.
    TurnDeg(f64),
    /// Spin the dribbler at this speed (0: off), at once: `{ dribble_rpm = 3000.0 }`.
    DribbleRpm(f64),
    /// Arm the kicker, at once (it fires when the ball is at the dribbler):
    /// `{ kick = { speed_mm_s = 4000.0, angle_deg = 0.0 } }`.
    Kick(KickMove),
}

/// A kick of a script.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KickMove {
    /// Speed of the ball off the kicker, mm/s.
    pub speed_mm_s: f64,
    /// Angle above the floor, degrees (0: flat; above 0: a chip).
    #[serde(default)]
    pub angle_deg: f64,
}

/// A scripted drive (`[control.script]`), judged on dead reckoning.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ScriptConfig {
    /// The moves, in order.
    pub moves: Vec<Move>,
    /// Speed of the straight runs, mm/s.
    pub speed_mm_s: f64,
    /// Rate of the turns, deg/s.
    pub turn_rate_deg_s: f64,
    /// Standstill after each move, s.
    pub pause_s: f64,
}

impl Default for ScriptConfig {
    fn default() -> Self {
        Self {
            moves: Vec::new(),
            speed_mm_s: 150.0,
            turn_rate_deg_s: 45.0,
            pause_s: 0.5,
        }
    }
}

/// Where a script is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Moving; the dead-reckoned pose when the move began (x, y, heading).
    Moving([f64; 3]),
    /// Standing still after a move until this time.
    Pausing(f64),
}

/// Drives the moves of `[control.script]` one after the other on dead reckoning, each ending
/// at rest (the speed is the one from which the acceleration limit stops the robot over what is
/// left, less one period's travel), with a pause after each.
pub struct Script {
    script: ScriptConfig,
    accel_mm_s2: f64,
    angular_accel_rad_s2: f64,
    period_s: f64,
    index: usize,
    phase: Option<Phase>,
    /// Actuator commands of the moves done this cycle.
    actuators: Vec<ActuatorCommand>,
}

impl Script {
    /// The actuator command of a move that is one, done at once.
    fn actuator(m: Move) -> Option<ActuatorCommand> {
        match m {
            Move::DribbleRpm(rpm) => Some(ActuatorCommand::Dribble { rpm }),
            Move::Kick(k) => Some(ActuatorCommand::Kick {
                speed_mm_s: k.speed_mm_s,
                angle_rad: k.angle_deg.to_radians(),
            }),
            Move::ForwardMm(_) | Move::TurnDeg(_) => None,
        }
    }

    /// The speed from which `accel` stops over `left` after one more period, capped at `top`.
    fn approach(left: f64, accel: f64, period_s: f64, top: f64) -> f64 {
        let at = accel * period_s;
        (-at + (at * at + 2.0 * accel * left.max(0.0)).sqrt()).min(top)
    }
}

impl Controller for Script {
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand {
        let p = &s.odometry_pose;
        let now = [p.translation.x, p.translation.y, p.rotation.angle()];
        loop {
            let Some(&m) = self.script.moves.get(self.index) else {
                return BodyCommand::STOP;
            };
            if let Some(a) = Self::actuator(m) {
                self.actuators.push(a);
                self.index += 1;
                continue;
            }
            match self.phase {
                None => self.phase = Some(Phase::Moving(now)),
                Some(Phase::Pausing(until)) => {
                    if s.t_s < until {
                        return BodyCommand::STOP;
                    }
                    self.index += 1;
                    self.phase = None;
                }
                Some(Phase::Moving(start)) => {
                    let (left, top, accel, command): (f64, f64, f64, fn(f64) -> BodyCommand) =
                        match m {
                            Move::DribbleRpm(_) | Move::Kick(_) => continue,
                            Move::ForwardMm(d) => {
                                let (dx, dy) = (now[0] - start[0], now[1] - start[1]);
                                let along = dx * start[2].cos() + dy * start[2].sin();
                                (
                                    d.abs() - along * d.signum(),
                                    self.script.speed_mm_s,
                                    self.accel_mm_s2,
                                    BodyCommand::forward,
                                )
                            }
                            Move::TurnDeg(a) => {
                                let a = a.to_radians();
                                let turned = wrap_pi(now[2] - start[2]);
                                (
                                    a.abs() - turned * a.signum(),
                                    self.script.turn_rate_deg_s.to_radians(),
                                    self.angular_accel_rad_s2,
                                    BodyCommand::turn,
                                )
                            }
                        };
                    let done = match m {
                        Move::TurnDeg(_) => left < 0.05f64.to_radians(),
                        _ => left < 0.5,
                    };
                    if done {
                        self.phase = Some(Phase::Pausing(s.t_s + self.script.pause_s));
                        return BodyCommand::STOP;
                    }
                    let sign = match m {
                        Move::ForwardMm(d) | Move::TurnDeg(d) => d.signum(),
                        _ => 1.0,
                    };
                    return command(sign * Self::approach(left, accel, self.period_s, top));
                }
            }
        }
    }

    fn actuators(&mut self) -> Vec<ActuatorCommand> {
        std::mem::take(&mut self.actuators)
    }

    fn step(&self) -> Option<usize> {
        (!self.script.moves.is_empty()).then_some(self.index)
    }
}
