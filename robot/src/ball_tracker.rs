//! The ball as the robot keeps it between sightings: a Kalman filter on its position and
//! velocity in the odometry frame, so that the robot's own motion (dead-reckoned) is taken out
//! and the ball stays put where the robot turned away from it.
//!
//! State `x = [px, py, vx, vy]` (mm, mm/s). Prediction over `dt` rolls the ball on at its
//! velocity while the floor slows it at the rolling deceleration `a` (the league's two-phase
//! model, its second phase: 350 mm/s^2 by default), speed `s' = max(0, s - a dt)`, position
//! advanced by the mean of `s` and `s'`; the covariance grows by white acceleration noise
//! `q` (`Q = q [dt^3/3 I, dt^2/2 I; dt^2/2 I, dt I]`), which also covers the faster-slowing
//! slide just after a kick. A sighting measures the position with its own covariance (range
//! and bearing sigmas turned into the odometry frame); the dribbler's light barrier measures it
//! at the dribbler, tightly, with the robot's own velocity. The filter is ours: no paper of the
//! project tracks a ball.

use nalgebra::{Isometry2, Matrix2, Matrix2x4, Matrix4, Point2, Vector2, Vector4};

/// Settings of the tracker (`[vision.ball]`'s `tracker`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrackerConfig {
    /// Rolling deceleration in the prediction, mm/s^2.
    pub roll_decel_mm_s2: f64,
    /// White acceleration noise density q, mm^2/s^3.
    pub accel_noise_mm2_s3: f64,
    /// Position sigma of the first sighting's velocity guess: its speed sigma, mm/s.
    pub initial_speed_sigma_mm_s: f64,
    /// Sightings farther than this many sigmas from the prediction are outliers; this many in a
    /// row (or one after the track went unseen for `max_unseen_s` / 4) restart the track there.
    pub gate_sigmas: f64,
    /// Outliers in a row that restart the track.
    pub outliers_to_restart: u32,
    /// The track is dropped after this long without a sighting, s.
    pub max_unseen_s: f64,
}

impl Default for TrackerConfig {
    fn default() -> Self {
        Self {
            roll_decel_mm_s2: 350.0,
            accel_noise_mm2_s3: 4.0e6,
            initial_speed_sigma_mm_s: 2000.0,
            gate_sigmas: 6.0,
            outliers_to_restart: 3,
            max_unseen_s: 4.0,
        }
    }
}

/// The tracked ball, odometry frame.
#[derive(Debug, Clone, PartialEq)]
pub struct BallTrack {
    /// State `[px, py, vx, vy]`.
    pub x: Vector4<f64>,
    /// Its covariance.
    pub p: Matrix4<f64>,
    /// When the ball was last measured, s.
    pub last_seen_s: f64,
    /// Time the state is at, s.
    pub t_s: f64,
}

impl BallTrack {
    /// Position, odometry frame, mm.
    pub fn position(&self) -> Point2<f64> {
        Point2::new(self.x[0], self.x[1])
    }

    /// Velocity, odometry frame, mm/s.
    pub fn velocity(&self) -> Vector2<f64> {
        Vector2::new(self.x[2], self.x[3])
    }

    /// One-sigma position error: the square root of the covariance's larger eigenvalue, mm.
    pub fn position_sigma_mm(&self) -> f64 {
        let c = self.p.fixed_view::<2, 2>(0, 0);
        let (a, b, d) = (c[(0, 0)], c[(0, 1)], c[(1, 1)]);
        let mean = 0.5 * (a + d);
        (mean + (0.25 * (a - d) * (a - d) + b * b).sqrt())
            .max(0.0)
            .sqrt()
    }
}

/// The ball tracker.
#[derive(Debug, Clone, PartialEq)]
pub struct BallTracker {
    config: TrackerConfig,
    track: Option<BallTrack>,
    /// Outliers in a row.
    outliers: u32,
}

impl BallTracker {
    /// A tracker that knows no ball yet.
    pub fn new(config: TrackerConfig) -> Self {
        Self {
            config,
            track: None,
            outliers: 0,
        }
    }

    /// The track, if a ball is known.
    pub fn track(&self) -> Option<&BallTrack> {
        self.track.as_ref()
    }

    /// Forgets the ball.
    pub fn reset(&mut self) {
        self.track = None;
    }

    /// Rolls the track on to `t_s`; drops it when unseen too long.
    pub fn predict(&mut self, t_s: f64) {
        let cfg = self.config;
        let Some(tr) = self.track.as_mut() else {
            return;
        };
        if t_s - tr.last_seen_s > cfg.max_unseen_s {
            self.track = None;
            return;
        }
        let dt = t_s - tr.t_s;
        if dt <= 0.0 {
            return;
        }
        let v = Vector2::new(tr.x[2], tr.x[3]);
        let s = v.norm();
        let s2 = (s - cfg.roll_decel_mm_s2 * dt).max(0.0);
        let dir = if s > 0.0 { v / s } else { Vector2::zeros() };
        // Time the ball still rolls within the step, and the distance it covers.
        let t_roll = if cfg.roll_decel_mm_s2 > 0.0 {
            (s / cfg.roll_decel_mm_s2).min(dt)
        } else {
            dt
        };
        let dist = 0.5 * (s + s2) * t_roll;
        let mut f = Matrix4::identity();
        f[(0, 2)] = dt;
        f[(1, 3)] = dt;
        let ratio = if s > 0.0 { s2 / s } else { 0.0 };
        f[(2, 2)] = ratio.max(0.0);
        f[(3, 3)] = ratio.max(0.0);
        tr.x = Vector4::new(
            tr.x[0] + dir.x * dist,
            tr.x[1] + dir.y * dist,
            dir.x * s2,
            dir.y * s2,
        );
        tr.p = f * tr.p * f.transpose() + process_noise(cfg.accel_noise_mm2_s3, dt);
        tr.t_s = t_s;
    }

    /// Takes a measurement of the ball's position `z` (odometry frame) with covariance `r` at
    /// `t_s` (after [`BallTracker::predict`] to it); `velocity` pins the velocity too (the
    /// dribbler's). A sighting beyond the gate restarts the track there.
    pub fn update(
        &mut self,
        t_s: f64,
        z: Point2<f64>,
        r: Matrix2<f64>,
        velocity: Option<Vector2<f64>>,
    ) {
        let cfg = self.config;
        let fresh = |v: Vector2<f64>, sv: f64| {
            let mut p = Matrix4::zeros();
            p.fixed_view_mut::<2, 2>(0, 0).copy_from(&r);
            p[(2, 2)] = sv * sv;
            p[(3, 3)] = sv * sv;
            BallTrack {
                x: Vector4::new(z.x, z.y, v.x, v.y),
                p,
                last_seen_s: t_s,
                t_s,
            }
        };
        let Some(tr) = self.track.as_mut() else {
            let (v, sv) = velocity.map_or((Vector2::zeros(), cfg.initial_speed_sigma_mm_s), |v| {
                (v, 50.0)
            });
            self.track = Some(fresh(v, sv));
            return;
        };
        let h = Matrix2x4::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0);
        let innovation = z.coords - Vector2::new(tr.x[0], tr.x[1]);
        let s = h * tr.p * h.transpose() + r;
        let Some(s_inv) = s.try_inverse() else {
            return;
        };
        if (innovation.transpose() * s_inv * innovation)[(0, 0)] > cfg.gate_sigmas.powi(2) {
            self.outliers += 1;
            let stale = t_s - tr.last_seen_s > 0.25 * cfg.max_unseen_s;
            if velocity.is_some() || stale || self.outliers >= cfg.outliers_to_restart {
                let v = velocity.unwrap_or_else(Vector2::zeros);
                self.track = Some(fresh(v, cfg.initial_speed_sigma_mm_s));
                self.outliers = 0;
            }
            return;
        }
        self.outliers = 0;
        let k = tr.p * h.transpose() * s_inv;
        tr.x += k * innovation;
        tr.p = (Matrix4::identity() - k * h) * tr.p;
        if let Some(v) = velocity {
            tr.x[2] = v.x;
            tr.x[3] = v.y;
            for i in 0..4 {
                for j in 2..4 {
                    tr.p[(i, j)] = 0.0;
                    tr.p[(j, i)] = 0.0;
                }
            }
            tr.p[(2, 2)] = 2500.0;
            tr.p[(3, 3)] = 2500.0;
        }
        tr.last_seen_s = t_s;
    }
}

/// `Q` of white acceleration noise of density `q` over `dt`.
fn process_noise(q: f64, dt: f64) -> Matrix4<f64> {
    let (a, b, c) = (q * dt.powi(3) / 3.0, q * dt * dt / 2.0, q * dt);
    Matrix4::new(
        a, 0.0, b, 0.0, //
        0.0, a, 0.0, b, //
        b, 0.0, c, 0.0, //
        0.0, b, 0.0, c,
    )
}

/// The covariance, odometry frame, of a sighting at `bearing_rad` (robot frame) with range and
/// bearing sigmas, seen from `pose` (the robot's odometry pose).
pub fn sighting_covariance(
    pose: &Isometry2<f64>,
    range_mm: f64,
    bearing_rad: f64,
    range_sigma_mm: f64,
    bearing_sigma_rad: f64,
) -> Matrix2<f64> {
    let angle = pose.rotation.angle() + bearing_rad;
    let (s, c) = angle.sin_cos();
    let rot = Matrix2::new(c, -s, s, c);
    let along = range_sigma_mm.max(1.0).powi(2);
    let across = (range_mm * bearing_sigma_rad).max(1.0).powi(2);
    rot * Matrix2::new(along, 0.0, 0.0, across) * rot.transpose()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tracker() -> BallTracker {
        BallTracker::new(TrackerConfig::default())
    }

    #[test]
    fn a_rolling_ball_is_followed_and_slows_at_the_rolling_deceleration() {
        let mut t = tracker();
        let r = Matrix2::identity() * 100.0;
        // A ball rolling along x at 1 m/s, slowing at 350 mm/s^2, seen every 40 ms.
        let truth = |ts: f64| {
            let v = (1000.0 - 350.0 * ts).max(0.0);
            (1000.0 * ts - 175.0 * ts * ts, v)
        };
        for k in 0..50 {
            let ts = k as f64 * 0.04;
            t.predict(ts);
            t.update(ts, Point2::new(truth(ts).0, 0.0), r, None);
        }
        let tr = t.track().unwrap();
        let (x, v) = truth(49.0 * 0.04);
        assert!((tr.x[0] - x).abs() < 15.0, "{tr:?} vs {x}");
        assert!((tr.x[2] - v).abs() < 60.0, "{tr:?} vs {v}");
        // Unseen for 1 s: the prediction follows the deceleration to within a few cm.
        t.predict(49.0 * 0.04 + 1.0);
        let (x1, _) = truth(49.0 * 0.04 + 1.0);
        let tr = t.track().unwrap();
        assert!((tr.x[0] - x1).abs() < 40.0, "{tr:?} vs {x1}");
        assert!(tr.position_sigma_mm() > 10.0);
    }

    #[test]
    fn a_far_sighting_restarts_the_track_and_an_old_one_is_dropped() {
        let mut t = tracker();
        let r = Matrix2::identity() * 100.0;
        t.update(0.0, Point2::new(0.0, 0.0), r, None);
        t.predict(0.04);
        t.update(0.04, Point2::new(3000.0, 0.0), r, None);
        assert_eq!(
            t.track().unwrap().position(),
            Point2::new(0.0, 0.0),
            "one outlier"
        );
        for k in 2..4 {
            t.predict(0.04 * k as f64);
            t.update(0.04 * k as f64, Point2::new(3000.0, 0.0), r, None);
        }
        assert_eq!(t.track().unwrap().position(), Point2::new(3000.0, 0.0));
        t.predict(10.0);
        assert!(t.track().is_none());
    }

    #[test]
    fn the_covariance_is_long_along_the_ray() {
        let c = sighting_covariance(
            &Isometry2::new(Vector2::zeros(), 0.5),
            1000.0,
            0.0,
            30.0,
            0.001,
        );
        let along = Vector2::new(0.5f64.cos(), 0.5f64.sin());
        let var = (along.transpose() * c * along)[(0, 0)];
        assert!((var - 900.0).abs() < 1e-6);
    }
}
