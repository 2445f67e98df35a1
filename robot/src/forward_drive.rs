//! Controllers of a small differential-drive robot with a forward camera (Ahmed, Saatchi and
//! Caparrelli): avoidance by ground segmentation and by flow balance, and scripted moves.
//! Every command goes straight ahead or turns on the spot.

use crate::boundary::BodyCommand;
use crate::config::{ForwardDriveConfig, Move, RobotConfig, ScriptConfig};
use crate::controller::{Controller, Situation};
use nalgebra::Vector2;
use omniloop_control::wrap_pi;

fn straight(speed_mm_s: f64) -> BodyCommand {
    BodyCommand::translate(Vector2::new(speed_mm_s, 0.0))
}

fn turn(rate_rad_s: f64) -> BodyCommand {
    BodyCommand {
        v_mm_s: Vector2::zeros(),
        omega_rad_s: rate_rad_s,
    }
}

/// Sect. 2.1.1: straight while the ground ahead is clear; else turn on the spot toward the
/// side with more ground, and keep turning that way until the ground ahead reaches
/// `hysteresis_px` beyond what is needed (the paper says nothing of how long a turn lasts).
pub struct Segmentation {
    drive: ForwardDriveConfig,
    turning: Option<f64>,
}

impl Segmentation {
    /// The controller of `config`.
    pub fn new(config: &RobotConfig) -> Self {
        Self {
            drive: config.control.forward.clone(),
            turning: None,
        }
    }
}

impl Controller for Segmentation {
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand {
        let Some(g) = s.ground else {
            return BodyCommand::STOP;
        };
        let enough = match self.turning {
            Some(_) => g.ahead_px > g.needed_px + self.drive.hysteresis_px,
            None => g.clear_ahead(),
        };
        if enough {
            self.turning = None;
            return straight(self.drive.speed_mm_s);
        }
        let side = *self
            .turning
            .get_or_insert(if g.left_px >= g.right_px { 1.0 } else { -1.0 });
        turn(side * self.drive.turn_rate_deg_s.to_radians())
    }
}

/// Sect. 2.1.2: straight until the mean flow magnitude passes the threshold, then a turn on the
/// spot of `flow_turn_s` away from the side with the stronger flow; the flow of the frames
/// during and just after a turn is the turn's own and is not read.
pub struct FlowAvoidance {
    drive: ForwardDriveConfig,
    threshold_px: f32,
    /// Direction and end time of the turn under way.
    turn: Option<(f64, f64)>,
    settle: u32,
}

impl FlowAvoidance {
    /// The controller of `config`.
    pub fn new(config: &RobotConfig) -> Self {
        Self {
            drive: config.control.forward.clone(),
            threshold_px: config.vision.forward.flow.threshold_px,
            turn: None,
            settle: 0,
        }
    }
}

impl Controller for FlowAvoidance {
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand {
        let rate = self.drive.turn_rate_deg_s.to_radians();
        if let Some((side, until)) = self.turn {
            if s.t_s < until {
                return turn(side * rate);
            }
            self.turn = None;
            self.settle = self.drive.flow_settle_frames;
        }
        if self.settle > 0 {
            self.settle -= 1;
            return straight(self.drive.speed_mm_s);
        }
        match s.flow {
            Some(f) if f.larger_px() > self.threshold_px => {
                let side = if f.left_px > f.right_px { -1.0 } else { 1.0 };
                self.turn = Some((side, s.t_s + self.drive.flow_turn_s));
                turn(side * rate)
            }
            _ => straight(self.drive.speed_mm_s),
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
}

impl Script {
    /// The controller of `config`.
    pub fn new(config: &RobotConfig) -> Self {
        Self {
            script: config.control.script.clone(),
            accel_mm_s2: config.body.accel_limit_mm_s2,
            angular_accel_rad_s2: config.body.angular_accel_limit_rad_s2,
            period_s: config.control_period_s,
            index: 0,
            phase: None,
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
                            Move::ForwardMm(d) => {
                                let (dx, dy) = (now[0] - start[0], now[1] - start[1]);
                                let along = dx * start[2].cos() + dy * start[2].sin();
                                (
                                    d.abs() - along * d.signum(),
                                    self.script.speed_mm_s,
                                    self.accel_mm_s2,
                                    |v| straight(v),
                                )
                            }
                            Move::TurnDeg(a) => {
                                let a = a.to_radians();
                                let turned = wrap_pi(now[2] - start[2]);
                                (
                                    a.abs() - turned * a.signum(),
                                    self.script.turn_rate_deg_s.to_radians(),
                                    self.angular_accel_rad_s2,
                                    |w| turn(w),
                                )
                            }
                        };
                    let done = match m {
                        Move::ForwardMm(_) => left < 0.5,
                        Move::TurnDeg(_) => left < 0.05f64.to_radians(),
                    };
                    if done {
                        self.phase = Some(Phase::Pausing(s.t_s + self.script.pause_s));
                        return BodyCommand::STOP;
                    }
                    let sign = match m {
                        Move::ForwardMm(d) | Move::TurnDeg(d) => d.signum(),
                    };
                    return command(sign * Self::approach(left, accel, self.period_s, top));
                }
            }
        }
    }

    fn step(&self) -> Option<usize> {
        (!self.script.moves.is_empty()).then_some(self.index)
    }
}
