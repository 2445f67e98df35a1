//! Watching a run as it goes: each [`CycleObserver`] registered in the run's options sees every
//! control cycle (the frames the robot got, the truth, what the robot believed and commanded)
//! after the cycle is recorded. It cannot change the run: a run with an observer is the run
//! without one, bit for bit. `omniloop run --mcap` and `--gif` are observers.

use super::record::TrajectoryRow;
use super::score::FloorRegionScore;
use omniloop_robot::{Estimates, Frame};
use omniloop_sim::World;
use omniloop_sim::render::TruthFrame;
use std::sync::{Arc, Mutex};

/// One control cycle as an observer sees it.
pub struct CycleView<'a> {
    /// The cycle's number, from 0.
    pub cycle: u64,
    /// Every robot with software: the one robot, or a team's in the scenario's order.
    pub robots: &'a [RobotCycle<'a>],
    /// The ball's true state and its description, when there is a ball.
    pub ball: Option<(&'a super::BallRow, &'a omniloop_sim::BallSpec)>,
    /// The scripted robots' (`[[other_robots]]`) bodies where they are.
    pub others: &'a [omniloop_sim::Solid],
}

/// One robot's control cycle.
pub struct RobotCycle<'a> {
    /// Its name.
    pub name: &'a str,
    /// Its row of `trajectory.csv`: time, true pose and velocity, command, estimated pose.
    pub row: &'a TrajectoryRow,
    /// What its software believed (its line of `estimates.jsonl`).
    pub estimates: &'a Estimates,
    /// The frames it got this cycle, stamped with when they were taken.
    pub frames: Vec<Frame<'a>>,
    /// With the truth traced: the truth of each of those frames, by camera.
    pub truth: Vec<(&'a str, &'a TruthFrame)>,
    /// With the truth traced: its floor region scored pixel by pixel, when it judged one.
    pub floor: Option<&'a FloorRegionScore>,
}

/// Something that watches a run: a log, a live view.
pub trait CycleObserver: Send {
    /// The world before the first cycle (its static scene) and the names of the robots with
    /// software (their bodies are the world's first robots, in this order).
    fn start(&mut self, world: &World, robots: &[String]) {
        let _ = (world, robots);
    }

    /// One cycle, after it was recorded.
    fn cycle(&mut self, view: &CycleView<'_>);
}

/// An observer shared between the run and whoever set it up (to read it back after the run).
#[derive(Clone)]
pub struct ObserverHandle(pub Arc<Mutex<dyn CycleObserver>>);

impl ObserverHandle {
    /// Shares `observer` with a run.
    pub fn new(observer: impl CycleObserver + 'static) -> Self {
        Self(Arc::new(Mutex::new(observer)))
    }

    /// Runs `f` on the observer (a poisoned lock still gives it: an observer only records).
    pub fn with<R>(&self, f: impl FnOnce(&mut dyn CycleObserver) -> R) -> R {
        let mut guard = self.0.lock().unwrap_or_else(|e| e.into_inner());
        f(&mut *guard)
    }
}

impl std::fmt::Debug for ObserverHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ObserverHandle")
    }
}
