//! Wall following on the free space vision finds, the boundary-following mode of the Bug
//! algorithms (Lumelsky and Stepanov, "Path-planning strategies for a point mobile automaton
//! moving amidst unknown obstacles of arbitrary shape", Algorithmica 2, 1987): with no goal,
//! the robot keeps a wall on one side at a set gap, as explorers and corridor baselines do.
//!
//! Each cycle it reads, on the free space (ours, as the paper gives no control law):
//! - `ahead`, the least surely free gap (`FreeSpace::clear_mm` less the body radius) within 30
//!   degrees of straight ahead; below `stop_mm` the robot turns on the spot away from the wall;
//! - the wall: the total-least-squares line through the obstacle points within 60 degrees of
//!   the wall side's normal, its angle `psi` to the heading (robot frame, counter-clockwise)
//!   and its gap `e + gap_mm` to the body.
//!
//! It then drives forward at `speed_mm_s` (slowed in proportion as `ahead` nears `stop_mm` over
//! `slow_mm`) and turns at `omega = k_psi psi + s k_e e` (s = +1 for a wall on the left),
//! clamped to `turn_rate_deg_s`. With `e' = s v psi` and `psi' = -omega`, the gap error obeys
//! `e'' + k_psi e' + v k_e e = 0`: the defaults (`k_e` = 0.005 /mm/s, `k_psi` = 3 /s at
//! 400 mm/s) damp it critically. With no wall beside it the robot circles toward its side at
//! half the turn rate until it finds one, and so wraps around a wall's end.

use crate::boundary::BodyCommand;
use crate::config::ControlSpec;
use crate::controller::{
    ControlTable, Controller, ControllerEntry, Situation, check_table, no_problems, settings,
};
use nalgebra::Vector2;
use omniloop_control::wrap_pi;
use omniloop_problem::{Problem, Problems};
use omniloop_vision::FreeSpace;
use serde::{Deserialize, Serialize};
use std::f64::consts::FRAC_PI_2;

/// The registry's entry.
pub const ENTRY: ControllerEntry = ControllerEntry {
    name: "wall_follow",
    summary: "keeps a wall on one side at a set gap, on the free space from the image (the \
              boundary following of the Bug algorithms, Lumelsky and Stepanov 1987)",
    tables: &[ControlTable {
        name: "wall_follow",
        check: check_wall_follow,
    }],
    needs_goal: false,
    stages: &[crate::perception::freespace::NAME],
    check_use: no_problems,
    build: |c| {
        Ok(Box::new(WallFollow {
            config: settings(c, "wall_follow")?,
            radius_mm: c.body.radius_mm,
        }))
    },
};

/// The side the wall is kept on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// The wall on the robot's left.
    Left,
    /// The wall on the robot's right.
    Right,
}

/// How the wall follower drives (`[control.wall_follow]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WallFollowConfig {
    /// The side of the wall.
    pub side: Side,
    /// Gap kept between the body and the wall, mm.
    pub gap_mm: f64,
    /// Cruising speed, mm/s.
    pub speed_mm_s: f64,
    /// The robot turns on the spot when the gap ahead is less than this, mm.
    pub stop_mm: f64,
    /// Over this much gap beyond `stop_mm` the speed rises from zero to cruising, mm.
    pub slow_mm: f64,
    /// `k_e`: turn rate per millimetre of gap error, rad/s/mm.
    pub gap_gain_rad_s_per_mm: f64,
    /// `k_psi`: turn rate per radian of the wall's angle to the heading, 1/s.
    pub align_gain_per_s: f64,
    /// Fastest turn, deg/s.
    pub turn_rate_deg_s: f64,
}

impl Default for WallFollowConfig {
    fn default() -> Self {
        Self {
            side: Side::Right,
            gap_mm: 250.0,
            speed_mm_s: 400.0,
            stop_mm: 200.0,
            slow_mm: 300.0,
            gap_gain_rad_s_per_mm: 0.005,
            align_gain_per_s: 3.0,
            turn_rate_deg_s: 90.0,
        }
    }
}

/// Parses and checks `[control.wall_follow]`.
fn check_wall_follow(spec: &ControlSpec) -> Vec<Problem> {
    check_table(
        spec,
        "wall_follow",
        |w: &WallFollowConfig, p: &mut Problems| {
            p.positive("gap_mm", w.gap_mm);
            p.positive("speed_mm_s", w.speed_mm_s);
            p.non_negative("stop_mm", w.stop_mm);
            p.positive("slow_mm", w.slow_mm);
            p.positive("gap_gain_rad_s_per_mm", w.gap_gain_rad_s_per_mm);
            p.non_negative("align_gain_per_s", w.align_gain_per_s);
            p.positive("turn_rate_deg_s", w.turn_rate_deg_s);
        },
    )
}

/// The wall follower.
pub struct WallFollow {
    config: WallFollowConfig,
    radius_mm: f64,
}

impl WallFollow {
    /// The least surely free gap to the body over the directions within `half_rad` of
    /// `centre_rad` (robot frame), mm.
    fn gap_mm(&self, fs: &FreeSpace, centre_rad: f64, half_rad: f64) -> f64 {
        fs.direction_rad
            .iter()
            .zip(&fs.clear_mm)
            .filter(|&(&a, _)| wrap_pi(a - centre_rad).abs() <= half_rad)
            .map(|(_, &d)| d - self.radius_mm)
            .fold(f64::INFINITY, f64::min)
    }

    /// The wall on side `sign`: its angle to the heading (in (-pi/2, pi/2]) and its gap to the
    /// body, mm; none when fewer than three obstacle points lie there or they span no line.
    fn wall(&self, fs: &FreeSpace, sign: f64) -> Option<(f64, f64)> {
        let normal = sign * FRAC_PI_2;
        let pts: Vec<Vector2<f64>> = (fs.obstacle_points.iter())
            .map(|p| p.coords)
            .filter(|p| wrap_pi(p.y.atan2(p.x) - normal).abs() <= 60f64.to_radians())
            .collect();
        if pts.len() < 3 {
            return None;
        }
        let mean = pts.iter().sum::<Vector2<f64>>() / pts.len() as f64;
        let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
        for d in pts.iter().map(|p| p - mean) {
            (sxx, sxy, syy) = (sxx + d.x * d.x, sxy + d.x * d.y, syy + d.y * d.y);
        }
        if sxx + syy < 1.0 {
            return None;
        }
        let psi = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        let gap = Vector2::new(-psi.sin(), psi.cos()).dot(&mean).abs() - self.radius_mm;
        Some((psi, gap))
    }
}

impl Controller for WallFollow {
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand {
        let Some(fs) = s.percept::<FreeSpace>() else {
            return BodyCommand::STOP;
        };
        let c = &self.config;
        let sign = match c.side {
            Side::Left => 1.0,
            Side::Right => -1.0,
        };
        let max_turn = c.turn_rate_deg_s.to_radians();
        let ahead = self.gap_mm(fs, 0.0, 30f64.to_radians());
        if ahead < c.stop_mm {
            return BodyCommand::turn(-sign * max_turn);
        }
        let omega = match self.wall(fs, sign) {
            Some((psi, gap)) => {
                c.align_gain_per_s * psi + sign * c.gap_gain_rad_s_per_mm * (gap - c.gap_mm)
            }
            None => sign * 0.5 * max_turn,
        };
        let speed = c.speed_mm_s * ((ahead - c.stop_mm) / c.slow_mm).min(1.0);
        BodyCommand {
            omega_rad_s: omega.clamp(-max_turn, max_turn),
            ..BodyCommand::forward(speed)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::percept::Percepts;
    use std::f64::consts::TAU;

    /// 64 directions, each surely free to `clear(direction)` mm from the axis, with an
    /// obstacle point there when that is nearer than the range.
    fn seen(clear: impl Fn(f64) -> f64) -> FreeSpace {
        let dirs: Vec<f64> = (0..64).map(|j| j as f64 * TAU / 64.0).collect();
        let clear_mm: Vec<f64> = dirs.iter().map(|&a| clear(a).min(1500.0)).collect();
        let obstacle_points = (dirs.iter().zip(&clear_mm))
            .filter(|&(_, &d)| d < 1500.0)
            .map(|(&a, &d)| nalgebra::Point2::new(d * a.cos(), d * a.sin()))
            .collect();
        FreeSpace {
            clear_mm,
            obstacle_points,
            direction_rad: dirs,
            range_mm: 1500.0,
            ..FreeSpace::default()
        }
    }

    /// A straight wall `d` mm to the right of the axis, its direction `psi` rad
    /// counter-clockwise from the heading.
    fn wall_right(d: f64, psi: f64) -> impl Fn(f64) -> f64 {
        // The wall's unit normal toward the robot, and the distance along a ray at `a`.
        let n = Vector2::new(-psi.sin(), psi.cos());
        move |a| {
            let cos = -Vector2::new(a.cos(), a.sin()).dot(&n);
            if cos > 0.05 { d / cos } else { 1500.0 }
        }
    }

    fn decide(fs: Option<&FreeSpace>) -> BodyCommand {
        let mut w = WallFollow {
            config: WallFollowConfig::default(),
            radius_mm: 90.0,
        };
        let mut percepts = Percepts::default();
        if let Some(fs) = fs {
            percepts.put(fs.clone());
        }
        w.decide(&Situation {
            percepts: &percepts,
            target_body_mm: None,
            target_mm: None,
            velocity_body_mm_s: nalgebra::Vector2::zeros(),
            pose: None,
            odometry_pose: nalgebra::Isometry2::identity(),
            t_s: 0.0,
            actuators: &[],
        })
    }

    #[test]
    fn steers_toward_a_far_wall_and_away_from_a_near_one() {
        // Gap 90 + 250 = 340 mm from the axis is the set point.
        let far = decide(Some(&seen(wall_right(700.0, 0.0))));
        assert!(far.v_mm_s.x > 0.0 && far.omega_rad_s < 0.0, "{far:?}");
        let near = decide(Some(&seen(wall_right(250.0, 0.0))));
        assert!(near.v_mm_s.x > 0.0 && near.omega_rad_s > 0.0, "{near:?}");
        let on = decide(Some(&seen(wall_right(340.0, 0.0))));
        assert!(
            on.omega_rad_s.abs() < 1e-6 && on.v_mm_s.x == 400.0,
            "{on:?}"
        );
    }

    #[test]
    fn turns_parallel_to_a_wall_it_heads_into() {
        // At the set gap, heading 20 degrees into the wall: turn left, by k_psi psi.
        let c = decide(Some(&seen(wall_right(340.0, 20f64.to_radians()))));
        let expected = 3.0 * 20f64.to_radians();
        assert!((c.omega_rad_s - expected).abs() < 0.02, "{c:?}");
    }

    #[test]
    fn turns_on_the_spot_away_from_the_wall_at_a_wall_ahead() {
        // Wall ahead 250 mm from the axis (160 mm from the body), wall on the right.
        let right = wall_right(340.0, 0.0);
        let fs = seen(|a| {
            let ahead = if a.cos() > 0.1 {
                250.0 / a.cos()
            } else {
                1500.0
            };
            ahead.min(right(a))
        });
        let c = decide(Some(&fs));
        assert_eq!(c.v_mm_s, nalgebra::Vector2::zeros());
        assert!(c.omega_rad_s > 1.0, "{c:?}");
    }

    #[test]
    fn circles_toward_its_side_with_no_wall_in_sight() {
        let c = decide(Some(&seen(|_| 1500.0)));
        assert!(c.v_mm_s.x > 0.0, "{c:?}");
        assert!(
            (c.omega_rad_s + 0.5 * 90f64.to_radians()).abs() < 1e-9,
            "{c:?}"
        );
    }

    #[test]
    fn stands_still_without_free_space() {
        assert_eq!(decide(None), BodyCommand::STOP);
    }
}
