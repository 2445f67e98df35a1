//! Experiment metrics computed from a run's trajectory.

use crate::record::TrajectoryRow;
use nalgebra::Vector2;

/// E1 corner metrics (`shared/EXPERIMENTS.md`, E1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerMetrics {
    /// `(K - p).u1` at the first cycle, after `v.u1` exceeded 200 mm/s, where `v.u1` falls below
    /// 75% of its running maximum; `None` if that never happens.
    pub turn_onset_mm: Option<f64>,
    /// `max (p - K).u1` over the run.
    pub overshoot_mm: f64,
}

/// The E1 metrics of a trajectory around the corner `k` with first-leg direction `u1` (unit).
pub fn corner_metrics(rows: &[TrajectoryRow], k: Vector2<f64>, u1: Vector2<f64>) -> CornerMetrics {
    let mut running_max = f64::NEG_INFINITY;
    let mut armed = false;
    let mut onset = None;
    let mut overshoot = f64::NEG_INFINITY;
    for r in rows {
        let p = Vector2::new(r.x_mm, r.y_mm);
        let v = Vector2::new(r.vx_mm_s, r.vy_mm_s);
        let along = v.dot(&u1);
        overshoot = overshoot.max((p - k).dot(&u1));
        running_max = running_max.max(along);
        if along > 200.0 {
            armed = true;
        }
        if onset.is_none() && armed && along < 0.75 * running_max {
            onset = Some((k - p).dot(&u1));
        }
    }
    CornerMetrics {
        turn_onset_mm: onset,
        overshoot_mm: overshoot,
    }
}

/// The median of `values` (`None` when empty).
pub fn median(values: &[f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(x: f64, y: f64, vx: f64, vy: f64) -> TrajectoryRow {
        TrajectoryRow {
            t_s: 0.0,
            x_mm: x,
            y_mm: y,
            theta_rad: 0.0,
            vx_mm_s: vx,
            vy_mm_s: vy,
            cmd_vx_mm_s: 0.0,
            cmd_vy_mm_s: 0.0,
            est_x_mm: None,
            est_y_mm: None,
            est_theta_rad: None,
        }
    }

    #[test]
    fn onset_and_overshoot_follow_their_definitions() {
        let rows = vec![
            row(-2500.0, 0.0, 0.0, 0.0),
            row(-2000.0, 0.0, 150.0, 0.0), // below 200: not armed yet
            row(-1500.0, 0.0, 400.0, 0.0),
            row(-1000.0, 0.0, 350.0, 50.0),  // 87.5% of the maximum
            row(-700.0, 50.0, 290.0, 100.0), // 72.5%: onset at (K - p).u1 = 700
            row(-300.0, 200.0, 100.0, 300.0),
            row(120.0, 300.0, -50.0, 300.0),
            row(60.0, 500.0, -200.0, 300.0),
        ];
        let m = corner_metrics(&rows, Vector2::zeros(), Vector2::new(1.0, 0.0));
        assert_eq!(m.turn_onset_mm, Some(700.0));
        assert_eq!(m.overshoot_mm, 120.0);
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
    }
}
