//! The mission: targets to pass in order (waypoints, then the goal), judged on the robot's own
//! pose estimate.

use crate::config::GoalSpec;
use nalgebra::{Isometry2, Point2};

/// Where the robot is going and how far it has come, by its own reckoning.
#[derive(Debug, Clone, PartialEq)]
pub struct Mission {
    targets: Vec<Point2<f64>>,
    /// A target is passed when the estimate is this close.
    accept_mm: f64,
    next: usize,
}

impl Mission {
    /// The targets of a `[goal]` table.
    pub fn new(goal: &GoalSpec) -> Self {
        Self {
            targets: goal.targets(),
            accept_mm: goal.tolerance_mm - goal.estimate_margin_mm,
            next: 0,
        }
    }

    /// Moves on past every target the estimate says is reached (within `tolerance_mm -
    /// estimate_margin_mm`). The goal (the last target) stays the target once reached: the
    /// robot holds on it.
    pub fn update(&mut self, estimate: Option<&Isometry2<f64>>) {
        let Some(e) = estimate else {
            return;
        };
        let here = Point2::from(e.translation.vector);
        while self.next + 1 < self.targets.len()
            && (self.targets[self.next] - here).norm() <= self.accept_mm
        {
            self.next += 1;
        }
    }

    /// The index of the target the robot is heading for.
    pub fn index(&self) -> usize {
        self.next
    }

    /// The target the robot is heading for (world frame).
    pub fn target(&self) -> Point2<f64> {
        self.targets[self.next]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn moves_on_when_the_estimate_is_within_tolerance_and_holds_the_goal() {
        let goal = GoalSpec {
            waypoints_mm: vec![[1000.0, 0.0], [1000.0, 50.0]],
            estimate_margin_mm: 20.0,
            ..GoalSpec::to([0.0, 0.0], 100.0)
        };
        let mut m = Mission::new(&goal);
        let at = |x: f64, y: f64| Isometry2::new(Vector2::new(x, y), 0.0);
        m.update(None);
        m.update(Some(&at(910.0, 0.0)));
        assert_eq!(m.index(), 0, "within the tolerance but not its margin");
        // Within tolerance of the first waypoint and of the second: both are passed.
        m.update(Some(&at(950.0, 10.0)));
        assert_eq!(m.index(), 2);
        assert_eq!(m.target(), Point2::new(0.0, 0.0));
        m.update(Some(&at(0.0, 0.0)));
        assert_eq!(m.index(), 2, "the goal stays the target");
    }
}
