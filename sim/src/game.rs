//! The game's events and figures, judged on the simulator's side at every physics step, never
//! told to the robots: kicks, touches, the dribbler catching and losing the ball, goals (the
//! ball wholly over the goal line between the posts), the ball leaving the field, dribbling
//! further than the rules allow (1 m) and the ball faster than their limit (6.5 m/s).

use crate::FieldSpec;
use crate::ball::{BallSpec, BallState};
use nalgebra::Point2;
use serde::Serialize;

/// The rules' longest dribble, mm.
pub const MAX_DRIBBLE_MM: f64 = 1000.0;

/// Which goal: the one at +x (yellow) or at -x (blue).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum GoalSide {
    /// The goal at +x.
    #[serde(rename = "+x")]
    PosX,
    /// The goal at -x.
    #[serde(rename = "-x")]
    NegX,
}

/// Why a dribbler let the ball go.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Release {
    /// The robot kicked it.
    Kick,
    /// Holding it asked for more pull than the dribbler has (turning or braking too hard).
    Pull,
    /// The dribbler stopped.
    DribblerOff,
}

/// One event of the game. Robots are the world's robot indices.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum BallEvent {
    /// A robot's kicker fired.
    Kick {
        /// When, s.
        t_s: f64,
        /// Who kicked.
        robot: usize,
        /// The kick's speed, mm/s.
        speed_mm_s: f64,
        /// Its angle above the floor, rad.
        angle_rad: f64,
    },
    /// A robot's body or dribbler touched the ball (a bounce off it, a catch).
    Touch {
        /// When, s.
        t_s: f64,
        /// Who.
        robot: usize,
    },
    /// A robot's dribbler caught the ball.
    Captured {
        /// When, s.
        t_s: f64,
        /// Who.
        robot: usize,
    },
    /// A robot's dribbler let the ball go.
    Released {
        /// When, s.
        t_s: f64,
        /// Who.
        robot: usize,
        /// How far the robot carried the ball from where it caught it, mm.
        dribbled_mm: f64,
        /// Why.
        cause: Release,
    },
    /// A goal.
    Goal {
        /// When, s.
        t_s: f64,
        /// Into which goal.
        goal: GoalSide,
        /// Who touched the ball last.
        by: Option<usize>,
    },
    /// The ball left the field over a touch or goal line, not into a goal.
    Out {
        /// When, s.
        t_s: f64,
        /// Where it crossed, mm.
        at_mm: [f64; 2],
        /// Who touched it last.
        by: Option<usize>,
    },
    /// A robot dribbled the ball further than the rules allow.
    DribbledTooFar {
        /// When, s.
        t_s: f64,
        /// Who.
        robot: usize,
    },
    /// The ball went faster than the rules allow.
    TooFast {
        /// When, s.
        t_s: f64,
        /// Its speed, mm/s.
        speed_mm_s: f64,
        /// Who touched it last.
        by: Option<usize>,
    },
}

/// What the game showed of the ball over a run (`summary.json`'s `ball`).
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct BallFigures {
    /// Kicks fired.
    pub kicks: usize,
    /// Goals, in order: the goal and who touched the ball last.
    pub goals: Vec<(GoalSide, Option<usize>)>,
    /// Times the ball left the field.
    pub outs: usize,
    /// Touches, a count a robot (by the world's robot index).
    pub touches: Vec<usize>,
    /// Time each robot held the ball on its dribbler, s.
    pub possession_s: Vec<f64>,
    /// The longest dribble, mm.
    pub longest_dribble_mm: f64,
    /// Times a robot dribbled further than the rules allow.
    pub dribbled_too_far: usize,
    /// The ball's top speed, mm/s.
    pub top_speed_mm_s: f64,
    /// Times it went faster than the rules allow.
    pub too_fast: usize,
    /// How far it travelled over the floor, mm.
    pub path_mm: f64,
}

/// Watches the ball every physics step and writes the events.
#[derive(Debug, Clone)]
pub struct Referee {
    field: Option<FieldSpec>,
    /// Whether the ball is in play (inside the field, or not yet judged out).
    in_play: bool,
    /// Whether it is over the speed limit now (an event when it goes over).
    over_limit: bool,
    last_touch: Option<usize>,
    events: Vec<BallEvent>,
    figures: BallFigures,
    last_position: Option<Point2<f64>>,
}

impl Referee {
    /// A referee for `robots` robots on `field` (none: no goals, no outs).
    pub fn new(field: Option<FieldSpec>, robots: usize) -> Self {
        Self {
            field,
            in_play: true,
            over_limit: false,
            last_touch: None,
            events: Vec::new(),
            figures: BallFigures {
                touches: vec![0; robots],
                possession_s: vec![0.0; robots],
                ..BallFigures::default()
            },
            last_position: None,
        }
    }

    /// Writes an event of the world (a kick, a touch, a catch, a loss) and keeps its figures.
    pub fn event(&mut self, e: BallEvent) {
        match e {
            BallEvent::Kick { robot, .. } => {
                self.figures.kicks += 1;
                self.touched(robot);
            }
            BallEvent::Touch { robot, .. } => {
                self.figures.touches[robot] += 1;
                self.touched(robot);
            }
            BallEvent::Captured { robot, .. } => self.touched(robot),
            BallEvent::Released { dribbled_mm, .. } => {
                self.figures.longest_dribble_mm = self.figures.longest_dribble_mm.max(dribbled_mm)
            }
            BallEvent::DribbledTooFar { .. } => self.figures.dribbled_too_far += 1,
            _ => {}
        }
        self.events.push(e);
    }

    fn touched(&mut self, robot: usize) {
        self.last_touch = Some(robot);
    }

    /// After a physics step of `dt_s` ending at `t_s`: the ball's state and who holds it.
    pub fn observe(
        &mut self,
        t_s: f64,
        dt_s: f64,
        spec: &BallSpec,
        ball: &BallState,
        holder: Option<usize>,
    ) {
        let p = ball.position_mm;
        if let Some(q) = self.last_position {
            self.figures.path_mm += (p - q).norm();
        }
        self.last_position = Some(p);
        if let Some(h) = holder {
            self.figures.possession_s[h] += dt_s;
        }
        let speed = ball.velocity_mm_s.norm().hypot(ball.vz_mm_s);
        self.figures.top_speed_mm_s = self.figures.top_speed_mm_s.max(speed);
        let over = speed > spec.speed_limit_mm_s + 1e-9;
        if over && !self.over_limit {
            self.figures.too_fast += 1;
            let by = self.last_touch;
            self.events.push(BallEvent::TooFast {
                t_s,
                speed_mm_s: speed,
                by,
            });
        }
        self.over_limit = over;
        self.judge_lines(t_s, spec, ball);
    }

    /// Goals and outs: the ball wholly over a line.
    fn judge_lines(&mut self, t_s: f64, spec: &BallSpec, ball: &BallState) {
        let Some(f) = &self.field else {
            return;
        };
        let p = ball.position_mm;
        let r = spec.radius_mm;
        let (a1, b) = (f.half_length_mm, f.half_width_mm);
        let beyond_x = p.x.abs() > a1 + r;
        let beyond_y = p.y.abs() > b + r;
        if !self.in_play {
            // Back in play once wholly inside the field again.
            self.in_play = p.x.abs() < a1 - r && p.y.abs() < b - r;
            return;
        }
        if !(beyond_x || beyond_y) {
            return;
        }
        self.in_play = false;
        let by = self.last_touch;
        let mouth = f.goal_width_mm / 2.0;
        let goal_height = f.goal_wall_height_mm;
        if beyond_x && !beyond_y && p.y.abs() < mouth - r && ball.height_mm + r < goal_height {
            let goal = if p.x > 0.0 {
                GoalSide::PosX
            } else {
                GoalSide::NegX
            };
            self.figures.goals.push((goal, by));
            self.events.push(BallEvent::Goal { t_s, goal, by });
        } else {
            self.figures.outs += 1;
            self.events.push(BallEvent::Out {
                t_s,
                at_mm: [p.x, p.y],
                by,
            });
        }
    }

    /// The events so far, in order.
    pub fn events(&self) -> &[BallEvent] {
        &self.events
    }

    /// The figures so far.
    pub fn figures(&self) -> &BallFigures {
        &self.figures
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    fn ball_at(x: f64, y: f64) -> BallState {
        BallState::on_floor(&BallSpec::default(), Point2::new(x, y), Vector2::zeros())
    }

    #[test]
    fn a_ball_wholly_over_the_goal_line_between_the_posts_is_a_goal_by_the_last_toucher() {
        let spec = BallSpec::default();
        let mut r = Referee::new(Some(FieldSpec::default()), 2);
        r.event(BallEvent::Touch { t_s: 0.1, robot: 1 });
        // On the line: not yet.
        r.observe(0.2, 0.002, &spec, &ball_at(1380.0, 0.0), None);
        assert!(
            r.events()
                .iter()
                .all(|e| !matches!(e, BallEvent::Goal { .. }))
        );
        r.observe(0.3, 0.002, &spec, &ball_at(1395.0, 100.0), None);
        assert_eq!(
            r.figures().goals,
            vec![(GoalSide::PosX, Some(1))],
            "{:?}",
            r.events()
        );
        // Staying in the goal is no second goal.
        r.observe(0.4, 0.002, &spec, &ball_at(1500.0, 100.0), None);
        assert_eq!(r.figures().goals.len(), 1);
    }

    #[test]
    fn a_ball_over_the_touch_line_or_beside_the_goal_is_out() {
        let spec = BallSpec::default();
        let mut r = Referee::new(Some(FieldSpec::default()), 1);
        r.observe(0.1, 0.002, &spec, &ball_at(0.0, 790.0), None);
        r.observe(0.2, 0.002, &spec, &ball_at(0.0, 0.0), None);
        r.observe(0.3, 0.002, &spec, &ball_at(-1400.0, 400.0), None);
        assert_eq!(r.figures().outs, 2, "{:?}", r.events());
        assert!(r.figures().goals.is_empty());
    }

    #[test]
    fn speed_over_the_limit_is_an_event_once_each_time() {
        let spec = BallSpec::default();
        let mut r = Referee::new(None, 1);
        let mut b = ball_at(0.0, 0.0);
        for v in [6000.0, 7000.0, 7100.0, 6000.0, 6600.0] {
            b.velocity_mm_s = Vector2::new(v, 0.0);
            r.observe(0.0, 0.002, &spec, &b, None);
        }
        assert_eq!(r.figures().too_fast, 2);
        assert_eq!(r.figures().top_speed_mm_s, 7100.0);
    }
}
