//! How a run with a goal ended, judged on the truth: the route's reachability on the true world
//! (computed once when the run starts) and the run's outcome (`reached`, `unreachable`,
//! `time_up`, `stuck`), so that a summary tells a robot that gave up honestly on a goal no
//! route reaches from one that wandered until its time ran out, and from one that stood still.

use nalgebra::Point2;
use omniloop_robot::GoalSpec;
use omniloop_sim::{Layout, Reachability, SimError, Target, reachability};
use serde::{Deserialize, Serialize};

/// The last stretch of a run judged for progress, s.
pub const PROGRESS_WINDOW_S: f64 = 15.0;
/// A new least distance to the current target counts as progress when it is this much below
/// the least before the window, mm.
pub const PROGRESS_NEW_LOW_MM: f64 = 100.0;
/// A net move over the window (or anywhere in a run shorter than it) counts as progress from
/// this length on, mm.
pub const PROGRESS_MOVE_MM: f64 = 200.0;

/// How a run with a goal ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GoalOutcome {
    /// Every target was reached (on the truth).
    Reached,
    /// The robot's planner reported the goal unreachable (the reason beside it).
    Unreachable,
    /// Time ran out while the robot still made progress (see [`made_progress`]).
    TimeUp,
    /// Time ran out and the robot made no progress in the last [`PROGRESS_WINDOW_S`]: a defect.
    Stuck,
}

impl GoalOutcome {
    /// The outcome as written in `summary.json` and the sweep's tables.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Reached => "reached",
            Self::Unreachable => "unreachable",
            Self::TimeUp => "time_up",
            Self::Stuck => "stuck",
        }
    }

    /// The outcome of a run: reached when every target was, else unreachable when the planner
    /// said so, else time up or stuck by whether it was `progressing` at the end.
    pub fn of(reached: bool, reported_unreachable: bool, progressing: bool) -> Self {
        match (reached, reported_unreachable, progressing) {
            (true, _, _) => Self::Reached,
            (false, true, _) => Self::Unreachable,
            (false, false, true) => Self::TimeUp,
            (false, false, false) => Self::Stuck,
        }
    }

    /// A team's outcome: its worst robot's, stuck before time up before unreachable before
    /// reached (so that a team is reached only when every robot is, and honest only when
    /// every robot is); `None` for no robot.
    pub fn worst(outcomes: impl IntoIterator<Item = Self>) -> Option<Self> {
        outcomes.into_iter().max()
    }
}

/// The truth about a run with a goal (keys of `summary.json` and of a team's robot rows,
/// written only with a goal).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GoalFigures {
    /// How the run ended.
    pub outcome: GoalOutcome,
    /// With `outcome` unreachable: the planner's reason (`no_route`, `too_narrow`,
    /// `no_progress`); `null` otherwise (written, so that it stands beside `outcome` in a
    /// sweep's table).
    #[serde(default)]
    pub unreachable_reason: Option<String>,
    /// Whether the robot's disc can roll from its start through its targets on the true world
    /// (computed when the run starts; see [`omniloop_sim::reachability`]).
    pub goal_reachable: bool,
    /// The widest such route's least distance from the robot's edge to a solid, mm (`null`
    /// when no route reaches the goal).
    pub reachable_margin_mm: Option<f64>,
}

/// A moment of a run on the truth side: when, where the robot's centre was, and which target
/// it was on (the first not reached yet; the number of targets once all are).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProgressSample {
    /// Simulated time, s.
    pub t_s: f64,
    /// True x of the robot's centre, mm.
    pub x_mm: f64,
    /// True y, mm.
    pub y_mm: f64,
    /// The target it was on.
    pub target: usize,
}

impl ProgressSample {
    fn point(&self) -> Point2<f64> {
        Point2::new(self.x_mm, self.y_mm)
    }
}

/// Whether a run was making progress at its end, on the truth (`samples` in time order,
/// `targets` the waypoints then the goal). Within the last [`PROGRESS_WINDOW_S`] of the run,
/// any of: the target index advanced; the distance to the current target came to a new low
/// at least [`PROGRESS_NEW_LOW_MM`] below its least before the window; the robot's net move
/// from the window's start to its end is at least [`PROGRESS_MOVE_MM`]. A run shorter than the
/// window is progressing when it moved that far from its start at all. No sample: no
/// progress.
pub fn made_progress(samples: &[ProgressSample], targets: &[Point2<f64>]) -> bool {
    let (Some(first), Some(last)) = (samples.first(), samples.last()) else {
        return false;
    };
    let from_s = last.t_s - PROGRESS_WINDOW_S;
    if first.t_s > from_s {
        let start = first.point();
        return samples
            .iter()
            .any(|s| (s.point() - start).norm() >= PROGRESS_MOVE_MM);
    }
    // Samples up to the window's start, and those within it; `opening` is where it starts.
    let split = samples.partition_point(|s| s.t_s <= from_s);
    let opening = &samples[split - 1];
    if last.target > opening.target || (last.point() - opening.point()).norm() >= PROGRESS_MOVE_MM {
        return true;
    }
    let Some(&target) = targets.get(last.target) else {
        return true;
    };
    let least = |s: &[ProgressSample]| {
        s.iter()
            .map(|s| (s.point() - target).norm())
            .fold(f64::INFINITY, f64::min)
    };
    least(&samples[split..]) <= least(&samples[..split]) - PROGRESS_NEW_LOW_MM
}

/// The reachability of `goal`'s targets (waypoints, then the goal, each within its tolerance)
/// for a robot of `radius_mm` started at `start_mm` among `world`'s solids.
pub fn route_reachability(
    world: &Layout,
    radius_mm: f64,
    start_mm: Point2<f64>,
    goal: &GoalSpec,
) -> Result<Reachability, SimError> {
    let targets: Vec<Target> = goal
        .targets()
        .into_iter()
        .map(|point_mm| Target {
            point_mm,
            tolerance_mm: goal.tolerance_mm,
        })
        .collect();
    reachability(world, radius_mm, start_mm, &targets)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run of ten samples a second for `seconds`, at `place(t)` on target `target(t)`.
    fn run(
        seconds: f64,
        place: impl Fn(f64) -> (f64, f64),
        target: impl Fn(f64) -> usize,
    ) -> Vec<ProgressSample> {
        (0..=(seconds * 10.0) as usize)
            .map(|k| {
                let t_s = k as f64 / 10.0;
                let (x_mm, y_mm) = place(t_s);
                ProgressSample {
                    t_s,
                    x_mm,
                    y_mm,
                    target: target(t_s),
                }
            })
            .collect()
    }

    const GOALS: [Point2<f64>; 2] = [Point2::new(1000.0, 0.0), Point2::new(1000.0, 1000.0)];

    #[test]
    fn standing_still_for_the_last_window_is_stuck() {
        // Drove 500 mm towards the goal in 10 s, then stood for 50 s.
        let s = run(60.0, |t| (50.0 * t.min(10.0), 0.0), |_| 0);
        assert!(!made_progress(&s, &GOALS));
        assert_eq!(GoalOutcome::of(false, false, false), GoalOutcome::Stuck);
        // The same, its last 15 s still driving: progress.
        let s = run(60.0, |t| (50.0 * (t - 45.0).max(0.0), 0.0), |_| 0);
        assert!(made_progress(&s, &GOALS));
    }

    #[test]
    fn circling_in_place_is_stuck_and_a_new_low_is_progress() {
        // Circles of 90 mm radius about the start: never 200 mm net, never nearer the goal.
        let circle = |t: f64| (90.0 * t.cos(), 90.0 * t.sin());
        assert!(!made_progress(&run(60.0, circle, |_| 0), &GOALS));
        // A circle that drifts 12 mm/s towards the goal in the last window: a new low over
        // 100 mm below the old one, though never 200 mm net.
        let drifting = |t: f64| {
            let (x, y) = circle(t);
            (x + 12.0 * (t - 45.0).max(0.0), y)
        };
        assert!(made_progress(&run(60.0, drifting, |_| 0), &GOALS));
        // At 4 mm/s: not enough.
        let creeping = |t: f64| {
            let (x, y) = circle(t);
            (x + 4.0 * (t - 45.0).max(0.0), y)
        };
        assert!(!made_progress(&run(60.0, creeping, |_| 0), &GOALS));
    }

    #[test]
    fn a_target_reached_in_the_window_is_progress() {
        // Stands still, but the target index advanced 5 s before the end.
        let s = run(60.0, |_| (1000.0, 0.0), |t| usize::from(t >= 55.0));
        assert!(made_progress(&s, &GOALS));
        // Advanced 20 s before the end: no longer.
        let s = run(60.0, |_| (1000.0, 0.0), |t| usize::from(t >= 40.0));
        assert!(!made_progress(&s, &GOALS));
    }

    #[test]
    fn a_run_shorter_than_the_window_must_have_moved() {
        assert!(!made_progress(
            &run(10.0, |t| (10.0 * t, 0.0), |_| 0),
            &GOALS
        ));
        assert!(made_progress(
            &run(10.0, |t| (30.0 * t, 0.0), |_| 0),
            &GOALS
        ));
        assert!(!made_progress(&[], &GOALS));
    }

    #[test]
    fn outcomes_rank_and_read_as_written() {
        assert_eq!(GoalOutcome::of(true, true, false), GoalOutcome::Reached);
        assert_eq!(
            GoalOutcome::of(false, true, false),
            GoalOutcome::Unreachable
        );
        assert_eq!(GoalOutcome::of(false, false, true), GoalOutcome::TimeUp);
        let team = [GoalOutcome::Reached, GoalOutcome::Unreachable];
        assert_eq!(GoalOutcome::worst(team), Some(GoalOutcome::Unreachable));
        let team = [GoalOutcome::TimeUp, GoalOutcome::Unreachable];
        assert_eq!(GoalOutcome::worst(team), Some(GoalOutcome::TimeUp));
        assert_eq!(GoalOutcome::worst([]), None);
        for o in [
            GoalOutcome::Reached,
            GoalOutcome::Unreachable,
            GoalOutcome::TimeUp,
            GoalOutcome::Stuck,
        ] {
            let json = serde_json::to_value(o).unwrap();
            assert_eq!(json, serde_json::json!(o.as_str()));
        }
    }

    #[test]
    fn the_route_of_a_goal_takes_its_waypoints() {
        let world = Layout {
            field: Some(omniloop_sim::FieldSpec::default()),
            ..Layout::default()
        };
        let start = Point2::new(-500.0, 0.0);
        let goal = GoalSpec::to([500.0, 0.0], 100.0);
        let open = route_reachability(&world, 90.0, start, &goal).unwrap();
        assert!(open.reachable);
        // A waypoint in the goal pocket behind the field's end wall, 20 mm from its back:
        // not a place the robot fits.
        let pocket = GoalSpec {
            waypoints_mm: vec![[1530.0, 0.0]],
            ..GoalSpec::to([500.0, 0.0], 10.0)
        };
        let r = route_reachability(&world, 90.0, start, &pocket).unwrap();
        assert!(!r.reachable);
    }
}
