//! A trial watched and scored on the simulator's side, by the rules' points: touching the ball
//! +1, touching it with the dribbler +1; stage 1: stopped holding the ball at the end +1;
//! stages 2 and 3: the ball into the attacked goal's defense area +1, into the goal +1, the
//! robot (any part of it) into a defense area -1; the moving ball: touch and dribbler touch.
//! The time is that of the trial's last point.

use super::trials::{Field, ROBOT_RADIUS_MM, Stage};
use crate::run::Simulation;
use nalgebra::Point2;
use omniloop_sim::game::{BallEvent, GoalSide};
use serde::Serialize;

/// How long the robot must stand with the ball on its dribbler to end stage 1, s.
const HOLD_S: f64 = 0.5;

/// What a trial earned.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrialScore {
    /// The trial's seed.
    pub seed: u64,
    /// Its points.
    pub points: i32,
    /// The robot touched the ball.
    pub touched: bool,
    /// Its dribbler caught the ball.
    pub dribbler: bool,
    /// Stage 1: it stood still holding the ball at the end.
    pub held_at_end: bool,
    /// The ball entered the attacked goal's defense area.
    pub ball_in_defense_area: bool,
    /// The ball went into the attacked goal.
    pub goal: bool,
    /// The robot entered a defense area.
    pub robot_in_defense_area: bool,
    /// Time of its last point from FORCE_START, s (none without points).
    pub time_s: Option<f64>,
    /// Simulated time it lasted, s.
    pub duration_s: f64,
    /// The robot's path, mm.
    #[serde(skip)]
    pub robot_path: Vec<Point2<f64>>,
    /// The ball's path, mm.
    #[serde(skip)]
    pub ball_path: Vec<Point2<f64>>,
}

/// Watches a trial cycle by cycle.
pub struct Watch {
    stage: Stage,
    field: Field,
    score: TrialScore,
    /// Since when the robot has stood holding the ball.
    standing_since: Option<f64>,
}

impl Watch {
    /// Before FORCE_START.
    pub fn new(stage: Stage, field: Field, seed: u64) -> Self {
        Self {
            stage,
            field,
            score: TrialScore {
                seed,
                points: 0,
                touched: false,
                dribbler: false,
                held_at_end: false,
                ball_in_defense_area: false,
                goal: false,
                robot_in_defense_area: false,
                time_s: None,
                duration_s: 0.0,
                robot_path: Vec::new(),
                ball_path: Vec::new(),
            },
            standing_since: None,
        }
    }

    /// Takes the state after a cycle; whether the trial is over.
    pub fn observe(&mut self, sim: &Simulation) -> bool {
        let world = sim.world();
        let t = world.time_s();
        let truth = sim.truth();
        let robot = Point2::from(truth.pose.translation.vector);
        self.score.robot_path.push(robot);
        let Some((_, ball)) = world.ball() else {
            return true;
        };
        self.score.ball_path.push(ball.position_mm);
        self.score.duration_s = t;
        let s = &mut self.score;
        for e in world.ball_events() {
            match *e {
                BallEvent::Touch { robot: 0, .. } => s.touched = true,
                BallEvent::Captured { robot: 0, .. } => (s.touched, s.dribbler) = (true, true),
                BallEvent::Goal {
                    goal: GoalSide::PosX,
                    ..
                } => s.goal = true,
                _ => {}
            }
        }
        let attacked =
            ball.position_mm.x > 0.0 && self.field.in_defense_area(ball.position_mm, 0.0);
        s.ball_in_defense_area |= attacked;
        s.robot_in_defense_area |= self.field.body_touches_defense_area(robot, ROBOT_RADIUS_MM);
        let holding = world.ball_holder() == Some(0);
        let still = truth.velocity_mm_s.norm() < 20.0;
        self.standing_since = match (holding && still, self.standing_since) {
            (true, None) => Some(t),
            (true, since) => since,
            (false, _) => None,
        };
        s.held_at_end = self.standing_since.is_some_and(|since| t - since >= HOLD_S);
        let points = self.points();
        if points > self.score.points {
            self.score.time_s = Some(t);
        }
        self.score.points = points;
        match self.stage {
            Stage::Grab => self.score.held_at_end,
            Stage::EmptyGoal | Stage::Defended => self.score.goal,
            Stage::MovingBall => self.score.dribbler,
        }
    }

    /// The points so far.
    fn points(&self) -> i32 {
        let s = &self.score;
        let base = i32::from(s.touched) + i32::from(s.dribbler);
        match self.stage {
            Stage::Grab => base + i32::from(s.held_at_end),
            Stage::MovingBall => base,
            Stage::EmptyGoal | Stage::Defended => {
                base + i32::from(s.ball_in_defense_area) + i32::from(s.goal)
                    - i32::from(s.robot_in_defense_area)
            }
        }
    }

    /// The trial's score.
    pub fn finish(self) -> TrialScore {
        self.score
    }
}
