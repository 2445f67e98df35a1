//! The robot's pose estimate: dead reckoning of the wheel odometry, corrected by the fixes its
//! perception stages give (a complementary filter with gating).
//!
//! The estimate is kept as an *anchor*, a pose and the dead-reckoned pose at the moment it was
//! set; the estimate is the anchor moved on by the odometry since. A fix of any kind sets a new
//! anchor between the prediction and the measurement:
//! - full pose: the solution nearer the prediction (of the pose and its alternative) is pulled
//!   toward by `gain`, position and heading; the first fix after the pose was unknown or given
//!   only as the start must be unambiguous and is taken as it is;
//! - heading only: the heading is pulled toward the measurement, the position kept;
//! - position only: the position is pulled toward the measurement, the heading kept;
//! - relative motion since the previous cycle: the motion the odometry measured over that cycle
//!   is pulled toward the measured one, and the estimate of the previous cycle moved by it.
//!
//! Measurements farther from the prediction than the gate (400 mm, 20 degrees) are not trusted.
//!
//! A pose fix that comes with its expected position error `s` (trilateration's) pulls the
//! position by the Kalman gain `k = P / (P + s^2)` instead, where `P` is the variance of the
//! estimate's position: `s^2` after the first such fix, `(1 - k) P` after each, grown by
//! `(0.05 d)^2` for every `d` mm the odometry moves (our choice: 5% of the distance, one sigma).
//! Fixes of a robot standing still are then averaged rather than followed, so errors that
//! change with its heading (pixel quantization of far landmarks) cancel.

use crate::boundary::OdometryReading;
use crate::estimates::{FixOutcome, Measurement};
use nalgebra::{Isometry2, Vector2};
use omniloop_control::{DeadReckoning, wrap_pi};

/// A measurement farther than this from the prediction is not trusted, mm.
const GATE_MM: f64 = 400.0;
/// ... or turned by more than this, rad (20 degrees).
const GATE_RAD: f64 = 0.35;
/// Position error the odometry adds per millimetre driven (one sigma).
const ODOMETRY_DRIFT: f64 = 0.05;

/// Why the estimator did not use a fix (its text is the `why` of a rejected fix in
/// `estimates.jsonl`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Rejection {
    /// The fix is farther from the prediction than the gate.
    #[error(
        "{distance_mm:.0} mm and {:.1} deg from the prediction (gate {} mm, {:.0} deg)",
        .turn_rad.to_degrees(),
        GATE_MM,
        GATE_RAD.to_degrees()
    )]
    OutsideGate {
        /// Distance from the prediction, mm.
        distance_mm: f64,
        /// Turn from the predicted heading, rad.
        turn_rad: f64,
    },
    /// An ambiguous pose fix before any fix has set the estimate.
    #[error("the image does not tell the two solutions apart and no fix has set the estimate yet")]
    Ambiguous,
    /// A heading fix while the position is unknown.
    #[error("the position is unknown: a heading alone cannot set the pose")]
    PositionUnknown,
    /// A position fix while the heading is unknown.
    #[error("the heading is unknown: a position alone cannot set the pose")]
    HeadingUnknown,
    /// A partial fix while the pose is unknown.
    #[error("the pose is unknown: a partial fix cannot set it")]
    PoseUnknown,
    /// A motion fix without an earlier cycle of known pose.
    #[error("no earlier cycle with a known pose to measure the motion from")]
    NoEarlierCycle,
}

/// The pose the estimate was last set to, and the dead-reckoned pose at that moment (`None`:
/// the origin of dead reckoning, i.e. the start).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Anchor {
    pose: Isometry2<f64>,
    odometry: Option<Isometry2<f64>>,
}

/// Tracks the robot's pose in the world frame from what its sensors give.
#[derive(Debug, Clone)]
pub struct PoseEstimator {
    reckoning: DeadReckoning,
    anchor: Option<Anchor>,
    anchored_by_fix: bool,
    takes_fixes: bool,
    gain: f64,
    /// The estimate and the dead-reckoned pose at the end of the previous cycle.
    last_cycle: Option<(Isometry2<f64>, Isometry2<f64>)>,
    /// Variance of the estimate's position, mm^2, once a fix with an expected error set it.
    position_var_mm2: Option<f64>,
    used: usize,
    rejected: usize,
}

impl PoseEstimator {
    /// An estimator for a robot told it starts at `start` (world frame). When it `takes_fixes`
    /// (any pose source but odometry) each fix pulls the estimate by `gain`.
    pub fn new(start: Isometry2<f64>, takes_fixes: bool, gain: f64) -> Self {
        Self {
            reckoning: DeadReckoning::new(),
            anchor: Some(Anchor {
                pose: start,
                odometry: None,
            }),
            anchored_by_fix: false,
            takes_fixes,
            gain,
            last_cycle: None,
            position_var_mm2: None,
            used: 0,
            rejected: 0,
        }
    }

    /// Takes a wheel odometry reading (integrated with the trapezoidal rule).
    pub fn odometry(&mut self, r: &OdometryReading) {
        self.reckoning.update(r.v_body_mm_s, r.omega_rad_s, r.dt_s);
        if let Some(v) = &mut self.position_var_mm2 {
            *v += (ODOMETRY_DRIFT * r.v_body_mm_s.norm() * r.dt_s).powi(2);
        }
    }

    /// The dead-reckoned pose in the odometry frame (the start at the origin), which fixes do
    /// not move: the frame of short-term memories.
    pub fn odometry_pose(&self) -> Isometry2<f64> {
        self.reckoning.pose()
    }

    /// The measured body velocity.
    pub fn velocity_body_mm_s(&self) -> Vector2<f64> {
        self.reckoning.velocity_body_mm_s()
    }

    /// The pose estimate in the world frame; `None` while the pose is unknown.
    pub fn estimate(&self) -> Option<Isometry2<f64>> {
        let a = self.anchor?;
        Some(match a.odometry {
            None => a.pose * self.reckoning.pose(),
            Some(o) => a.pose * (o.inverse() * self.reckoning.pose()),
        })
    }

    /// The robot was carried somewhere: its pose is unknown until an unambiguous fix.
    pub fn forget(&mut self) {
        self.anchor = None;
        self.anchored_by_fix = false;
        self.last_cycle = None;
        self.position_var_mm2 = None;
    }

    /// Marks the end of a control cycle (the reference of the next relative-motion fix).
    pub fn end_cycle(&mut self) {
        self.last_cycle = self.estimate().map(|e| (e, self.reckoning.pose()));
    }

    /// Whether a fix has set the estimate since the start (or since it was forgotten).
    pub fn has_fix(&self) -> bool {
        self.anchored_by_fix
    }

    /// Fixes used and rejected (by the gate) so far.
    pub fn fixes(&self) -> (usize, usize) {
        (self.used, self.rejected)
    }

    /// Folds in a measurement; says what became of it.
    pub fn fuse(&mut self, m: &Measurement) -> FixOutcome {
        self.fuse_with_error(m, None)
    }

    /// Folds in a measurement whose position is expected to be `expected_error_mm` off (one
    /// sigma) when known; says what became of it.
    pub fn fuse_with_error(
        &mut self,
        m: &Measurement,
        expected_error_mm: Option<f64>,
    ) -> FixOutcome {
        if !self.takes_fixes {
            return FixOutcome::Ignored;
        }
        let outcome = match *m {
            Measurement::Pose {
                pose,
                alternative,
                unambiguous,
            } => self.fuse_pose(pose, alternative, unambiguous, expected_error_mm),
            Measurement::Heading { heading_rad } => self.fuse_heading(heading_rad),
            Measurement::Position { position } => {
                let h = self.estimate().map(|p| p.rotation.angle());
                match h {
                    Some(h) => self.fuse_pose_parts(Some(position.coords), h, 0.0),
                    None => Err(Rejection::HeadingUnknown),
                }
            }
            Measurement::Motion { delta } => self.fuse_motion(delta),
        };
        match outcome {
            Ok(o) => {
                self.used += 1;
                o
            }
            Err(why) => FixOutcome::Rejected(why.to_string()),
        }
    }

    fn set(&mut self, pose: Isometry2<f64>) {
        self.anchor = Some(Anchor {
            pose,
            odometry: Some(self.reckoning.pose()),
        });
    }

    fn gate(&mut self, d_mm: f64, dh_rad: f64) -> Result<(), Rejection> {
        if d_mm > GATE_MM || dh_rad.abs() > GATE_RAD {
            self.rejected += 1;
            return Err(Rejection::OutsideGate {
                distance_mm: d_mm,
                turn_rad: dh_rad,
            });
        }
        Ok(())
    }

    fn fuse_pose(
        &mut self,
        pose: Isometry2<f64>,
        alternative: Option<Isometry2<f64>>,
        unambiguous: bool,
        expected_error_mm: Option<f64>,
    ) -> Result<FixOutcome, Rejection> {
        let fix_var = expected_error_mm.map(|s| (s * s).max(1e-6));
        let predicted = match self.estimate() {
            Some(p) if self.anchored_by_fix => p,
            _ => {
                if !unambiguous {
                    return Err(Rejection::Ambiguous);
                }
                self.set(pose);
                self.anchored_by_fix = true;
                self.position_var_mm2 = fix_var;
                return Ok(FixOutcome::Anchored);
            }
        };
        let d = |q: &Isometry2<f64>| (q.translation.vector - predicted.translation.vector).norm();
        let z = match alternative {
            Some(alt) if d(&alt) < d(&pose) => alt,
            _ => pose,
        };
        let dh = wrap_pi(z.rotation.angle() - predicted.rotation.angle());
        self.gate(d(&z), dh)?;
        let k = match (fix_var, self.position_var_mm2) {
            (Some(r), Some(p)) => {
                let k = p / (p + r);
                self.position_var_mm2 = Some((1.0 - k) * p);
                k
            }
            (Some(r), None) => {
                self.position_var_mm2 = Some(r);
                self.gain
            }
            (None, _) => self.gain,
        };
        let t = predicted.translation.vector
            + (z.translation.vector - predicted.translation.vector) * k;
        let h = predicted.rotation.angle() + self.gain * dh;
        self.set(Isometry2::new(t, h));
        Ok(FixOutcome::Used)
    }

    fn fuse_heading(&mut self, heading_rad: f64) -> Result<FixOutcome, Rejection> {
        let Some(p) = self.estimate() else {
            return Err(Rejection::PositionUnknown);
        };
        let dh = wrap_pi(heading_rad - p.rotation.angle());
        self.fuse_pose_parts(None, p.rotation.angle(), dh)
    }

    /// Pulls the position toward `position` (when given) and turns the heading `h` by
    /// `gain * dh`, after gating both.
    fn fuse_pose_parts(
        &mut self,
        position: Option<Vector2<f64>>,
        h: f64,
        dh: f64,
    ) -> Result<FixOutcome, Rejection> {
        let Some(p) = self.estimate() else {
            return Err(Rejection::PoseUnknown);
        };
        let here = p.translation.vector;
        let target = position.unwrap_or(here);
        self.gate((target - here).norm(), dh)?;
        self.set(Isometry2::new(
            here + (target - here) * self.gain,
            h + self.gain * dh,
        ));
        Ok(FixOutcome::Used)
    }

    fn fuse_motion(&mut self, delta: Isometry2<f64>) -> Result<FixOutcome, Rejection> {
        let Some((before, odo_before)) = self.last_cycle else {
            return Err(Rejection::NoEarlierCycle);
        };
        let odo_delta = odo_before.inverse() * self.reckoning.pose();
        let dt = delta.translation.vector - odo_delta.translation.vector;
        let dh = wrap_pi(delta.rotation.angle() - odo_delta.rotation.angle());
        self.gate(dt.norm(), dh)?;
        let fused = Isometry2::new(
            odo_delta.translation.vector + dt * self.gain,
            odo_delta.rotation.angle() + self.gain * dh,
        );
        self.set(before * fused);
        Ok(FixOutcome::Used)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point2;
    use std::f64::consts::PI;

    fn pose_fix(x: f64, y: f64, h: f64, unambiguous: bool) -> Measurement {
        Measurement::Pose {
            pose: Isometry2::new(Vector2::new(x, y), h),
            alternative: Some(Isometry2::new(Vector2::new(-x, -y), wrap_pi(h + PI))),
            unambiguous,
        }
    }

    fn drive(e: &mut PoseEstimator, vx: f64, omega: f64, seconds: f64) {
        e.odometry(&OdometryReading {
            v_body_mm_s: Vector2::new(vx, 0.0),
            omega_rad_s: omega,
            dt_s: 0.0,
        });
        e.odometry(&OdometryReading {
            v_body_mm_s: Vector2::new(vx, 0.0),
            omega_rad_s: omega,
            dt_s: seconds,
        });
    }

    fn x(e: &PoseEstimator) -> f64 {
        e.estimate().unwrap().translation.x
    }

    #[test]
    fn a_rejection_says_why_as_estimates_jsonl_writes_it() {
        let gate = Rejection::OutsideGate {
            distance_mm: 512.4,
            turn_rad: 0.1,
        };
        assert_eq!(
            gate.to_string(),
            "512 mm and 5.7 deg from the prediction (gate 400 mm, 20 deg)"
        );
        assert_eq!(
            Rejection::Ambiguous.to_string(),
            "the image does not tell the two solutions apart and no fix has set the estimate yet"
        );
    }

    #[test]
    fn fixes_with_an_expected_error_are_averaged_while_standing_and_followed_after_driving() {
        let start = Isometry2::new(Vector2::new(0.0, 0.0), 0.0);
        let mut e = PoseEstimator::new(start, true, 0.3);
        let fix = |x: f64| Measurement::Pose {
            pose: Isometry2::new(Vector2::new(x, 0.0), 0.0),
            alternative: None,
            unambiguous: true,
        };
        // Standing still: fixes 60 mm either side of the truth, each told 50 mm off.
        for k in 0..40 {
            let x = if k % 2 == 0 { 60.0 } else { -60.0 };
            assert_ne!(e.fuse_with_error(&fix(x), Some(50.0)), FixOutcome::Ignored);
        }
        // A fixed gain of 0.3 would end about 60 (1 - 0.3) / (1 + 0.7) = 25 mm off; the
        // variance-weighted mean of 40 fixes is within a few mm.
        assert!(x(&e).abs() < 5.0, "{}", x(&e));
        let settled = e.position_var_mm2.unwrap();
        assert!(settled < 50.0 * 50.0 / 30.0, "{settled}");
        // 2 m driven: the estimate is uncertain again and a fix moves it most of the way.
        drive(&mut e, 200.0, 0.0, 10.0);
        assert!(e.position_var_mm2.unwrap() > 90.0 * 90.0);
        let before = x(&e);
        e.fuse_with_error(&fix(before + 100.0), Some(50.0));
        assert!(x(&e) - before > 70.0, "{} -> {}", before, x(&e));
    }

    #[test]
    fn odometry_moves_the_estimate_and_pose_fixes_pull_it_back() {
        let start = Isometry2::new(Vector2::new(-500.0, 0.0), 0.0);
        let mut e = PoseEstimator::new(start, true, 0.5);
        // An ambiguous fix cannot set the estimate.
        assert!(matches!(
            e.fuse(&pose_fix(-400.0, 10.0, 0.0, false)),
            FixOutcome::Rejected(_)
        ));
        assert_eq!(
            e.fuse(&pose_fix(-490.0, 0.0, 0.0, true)),
            FixOutcome::Anchored
        );
        assert!((x(&e) + 490.0).abs() < 1e-9);
        drive(&mut e, 100.0, 0.0, 1.0);
        assert!((x(&e) + 390.0).abs() < 1e-6);
        // 20 mm ahead: half of it is taken; its half-turn twin is the one chosen.
        assert_eq!(e.fuse(&pose_fix(370.0, 0.0, PI, false)), FixOutcome::Used);
        assert!((x(&e) + 380.0).abs() < 1e-6, "{:?}", e.estimate());
        // Far off: rejected by the gate.
        assert!(matches!(
            e.fuse(&pose_fix(900.0, 500.0, 0.0, true)),
            FixOutcome::Rejected(_)
        ));
        assert_eq!(e.fixes(), (2, 1));
    }

    #[test]
    fn with_odometry_as_the_source_fixes_are_ignored() {
        let mut e = PoseEstimator::new(Isometry2::identity(), false, 0.5);
        assert_eq!(
            e.fuse(&pose_fix(100.0, 0.0, 0.0, true)),
            FixOutcome::Ignored
        );
        drive(&mut e, 50.0, 0.0, 2.0);
        assert!((x(&e) - 100.0).abs() < 1e-9);
    }

    #[test]
    fn a_forgotten_pose_is_unknown_until_an_unambiguous_fix() {
        let mut e = PoseEstimator::new(Isometry2::identity(), true, 0.3);
        e.forget();
        assert!(e.estimate().is_none());
        assert!(matches!(
            e.fuse(&Measurement::Heading { heading_rad: 0.1 }),
            FixOutcome::Rejected(_)
        ));
        assert!(matches!(
            e.fuse(&pose_fix(300.0, 0.0, 0.0, false)),
            FixOutcome::Rejected(_)
        ));
        assert_eq!(
            e.fuse(&pose_fix(300.0, 0.0, 0.0, true)),
            FixOutcome::Anchored
        );
        assert!((x(&e) - 300.0).abs() < 1e-12);
    }

    #[test]
    fn heading_and_position_fixes_correct_their_part_only() {
        let mut e = PoseEstimator::new(Isometry2::identity(), true, 0.5);
        assert_eq!(
            e.fuse(&Measurement::Heading { heading_rad: 0.2 }),
            FixOutcome::Used
        );
        let p = e.estimate().unwrap();
        assert!((p.rotation.angle() - 0.1).abs() < 1e-12);
        assert!(p.translation.vector.norm() < 1e-12);
        let m = Measurement::Position {
            position: Point2::new(40.0, -20.0),
        };
        assert_eq!(e.fuse(&m), FixOutcome::Used);
        let p = e.estimate().unwrap();
        assert!((p.translation.vector - Vector2::new(20.0, -10.0)).norm() < 1e-12);
        assert!((p.rotation.angle() - 0.1).abs() < 1e-12);
        // Across the +-pi seam the heading moves the short way.
        let mut e = PoseEstimator::new(Isometry2::new(Vector2::zeros(), PI - 0.05), true, 0.5);
        e.fuse(&Measurement::Heading {
            heading_rad: -PI + 0.05,
        });
        let h = e.estimate().unwrap().rotation.angle();
        assert!((h.abs() - PI).abs() < 1e-9, "{h}");
    }

    #[test]
    fn a_motion_fix_replaces_part_of_the_odometry_increment() {
        let mut e = PoseEstimator::new(Isometry2::identity(), true, 0.5);
        // No earlier cycle yet.
        let delta = Isometry2::new(Vector2::new(100.0, 0.0), 0.0);
        assert!(matches!(
            e.fuse(&Measurement::Motion { delta }),
            FixOutcome::Rejected(_)
        ));
        e.end_cycle();
        // Odometry says 80 mm forward; the camera says 100 mm and a 0.1 rad turn.
        drive(&mut e, 80.0, 0.0, 1.0);
        let delta = Isometry2::new(Vector2::new(100.0, 0.0), 0.1);
        assert_eq!(e.fuse(&Measurement::Motion { delta }), FixOutcome::Used);
        let p = e.estimate().unwrap();
        assert!((p.translation.x - 90.0).abs() < 1e-9, "{p:?}");
        assert!((p.rotation.angle() - 0.05).abs() < 1e-12);
    }
}
