//! A run paced to real time (`omniloop run --realtime`): the loop waits until the wall clock
//! has caught up with each cycle's simulation time, so a live viewer sees the robot move at its
//! own speed. Waiting changes nothing the run computes.

use crate::run::observer::{CycleObserver, CycleView};
use std::time::{Duration, Instant};

/// Holds each cycle until its simulation time has passed on the wall clock since the first.
#[derive(Debug, Default)]
pub struct RealTime {
    start: Option<Instant>,
}

impl CycleObserver for RealTime {
    fn cycle(&mut self, view: &CycleView<'_>) {
        let start = *self.start.get_or_insert_with(Instant::now);
        let t_s = view.robots.first().map_or(0.0, |r| r.row.t_s);
        let due = start + Duration::from_secs_f64(t_s.max(0.0));
        let now = Instant::now();
        if due > now {
            std::thread::sleep(due - now);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::TrajectoryRow;
    use omniloop_robot::Estimates;

    #[test]
    fn a_cycle_waits_for_its_simulation_time_since_the_first() {
        let row = |t_s| TrajectoryRow {
            t_s,
            x_mm: 0.0,
            y_mm: 0.0,
            theta_rad: 0.0,
            vx_mm_s: 0.0,
            vy_mm_s: 0.0,
            cmd_vx_mm_s: 0.0,
            cmd_vy_mm_s: 0.0,
            est_x_mm: None,
            est_y_mm: None,
            est_theta_rad: None,
        };
        let estimates = Estimates::default();
        let mut pace = RealTime::default();
        let begun = Instant::now();
        for (cycle, t_s) in [0.0, 0.04, 0.08].into_iter().enumerate() {
            let r = row(t_s);
            let robots = [crate::run::observer::RobotCycle {
                name: "robot",
                row: &r,
                estimates: &estimates,
                frames: Vec::new(),
                truth: Vec::new(),
                floor: None,
            }];
            let view = CycleView {
                cycle: cycle as u64,
                robots: &robots,
                ball: None,
                others: &[],
            };
            pace.cycle(&view);
        }
        let took = begun.elapsed().as_secs_f64();
        assert!((0.08..0.5).contains(&took), "{took} s for 0.08 s simulated");
    }
}
