//! What a run with a ball leaves behind, on the simulator's side: the ball's true state every
//! control cycle (`ball.csv`), the game's events (`events.jsonl`) and its figures
//! (`summary.json`'s `ball`), robots named as in the scenario.

use nalgebra::Point2;
use omniloop_sim::{BallEvent, BallFigures, GoalSide, World};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::Write;

/// The ball at the start of a control cycle (a row of `ball.csv`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BallRow {
    /// Simulated time, s.
    pub t_s: f64,
    /// Centre x, mm.
    pub x_mm: f64,
    /// Centre y, mm.
    pub y_mm: f64,
    /// Height of the centre above the floor, mm (the radius on the floor).
    pub z_mm: f64,
    /// Velocity x, mm/s.
    pub vx_mm_s: f64,
    /// Velocity y, mm/s.
    pub vy_mm_s: f64,
    /// Vertical velocity, mm/s.
    pub vz_mm_s: f64,
    /// The robot whose dribbler holds it, if one does.
    pub held_by: Option<String>,
}

/// The ball's records of a run: its state every cycle and the game's events, robots named.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BallOutput {
    /// A row a control cycle (and the final state).
    pub rows: Vec<BallRow>,
    /// The game's events, in order, robots named ([`named_event`]).
    pub events: Vec<serde_json::Value>,
}

/// Column names of `ball.csv`, in order.
pub const BALL_HEADER: &str = "t_s,x_mm,y_mm,z_mm,vx_mm_s,vy_mm_s,vz_mm_s,held_by";

impl BallRow {
    /// The ball of `world` now, robots named by `names` (the world's robot order).
    pub fn of(world: &World, names: &[String]) -> Option<Self> {
        let (_, b) = world.ball()?;
        Some(Self {
            t_s: world.time_s(),
            x_mm: b.position_mm.x,
            y_mm: b.position_mm.y,
            z_mm: b.height_mm,
            vx_mm_s: b.velocity_mm_s.x,
            vy_mm_s: b.velocity_mm_s.y,
            vz_mm_s: b.vz_mm_s,
            held_by: world.ball_holder().map(|i| robot_name(names, i)),
        })
    }

    /// Where it was over the floor.
    pub fn point(&self) -> Point2<f64> {
        Point2::new(self.x_mm, self.y_mm)
    }
}

/// The name of the world's robot `i`: its name, or `other_robots[k]` for a scripted one.
pub fn robot_name(names: &[String], i: usize) -> String {
    names
        .get(i)
        .cloned()
        .unwrap_or_else(|| format!("other_robots[{}]", i - names.len()))
}

/// Writes `ball.csv`: a header and a row a cycle, numbers in their shortest exact form.
pub fn write_ball_csv(rows: &[BallRow], mut w: impl Write) -> std::io::Result<()> {
    writeln!(w, "{BALL_HEADER}")?;
    for r in rows {
        writeln!(
            w,
            "{},{},{},{},{},{},{},{}",
            r.t_s,
            r.x_mm,
            r.y_mm,
            r.z_mm,
            r.vx_mm_s,
            r.vy_mm_s,
            r.vz_mm_s,
            r.held_by.as_deref().unwrap_or("")
        )?;
    }
    Ok(())
}

/// An event of the game with its robots named: the event's fields, `robot` and `by` as names.
pub fn named_event(e: &BallEvent, names: &[String]) -> serde_json::Value {
    let mut v = serde_json::to_value(e).unwrap_or_default();
    if let Some(map) = v.as_object_mut() {
        for key in ["robot", "by"] {
            if let Some(i) = map.get(key).and_then(serde_json::Value::as_u64) {
                map.insert(key.into(), robot_name(names, i as usize).into());
            }
        }
    }
    v
}

/// A goal of the run: into which goal, who touched the ball last.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GoalRow {
    /// `+x` or `-x`.
    pub goal: String,
    /// Who touched the ball last.
    pub by: Option<String>,
}

/// The ball's figures of a run (`summary.json`'s `ball`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BallSummary {
    /// Kicks fired.
    pub kicks: usize,
    /// Goals, in order.
    pub goals: Vec<GoalRow>,
    /// Times it left the field.
    pub outs: usize,
    /// Touches, by robot.
    pub touches: BTreeMap<String, usize>,
    /// Time each robot held it on its dribbler, s.
    pub possession_s: BTreeMap<String, f64>,
    /// The longest dribble, mm (the rules allow 1000).
    pub longest_dribble_mm: f64,
    /// Dribbles longer than the rules allow.
    pub dribbled_too_far: usize,
    /// Its top speed, mm/s.
    pub top_speed_mm_s: f64,
    /// Times it went faster than the rules allow.
    pub too_fast: usize,
    /// How far it travelled over the floor, mm.
    pub path_mm: f64,
    /// Where it ended, mm.
    pub final_mm: [f64; 2],
}

impl BallSummary {
    /// The figures of `world`'s ball, robots named by `names`, when it has a ball.
    pub fn of(world: &World, names: &[String]) -> Option<Self> {
        let f: &BallFigures = world.ball_figures()?;
        let (_, b) = world.ball()?;
        let by_robot = |i: usize| robot_name(names, i);
        Some(Self {
            kicks: f.kicks,
            goals: (f.goals.iter())
                .map(|(g, by)| GoalRow {
                    goal: match g {
                        GoalSide::PosX => "+x".into(),
                        GoalSide::NegX => "-x".into(),
                    },
                    by: by.map(by_robot),
                })
                .collect(),
            outs: f.outs,
            touches: (f.touches.iter().enumerate())
                .filter(|(_, n)| **n > 0)
                .map(|(i, n)| (by_robot(i), *n))
                .collect(),
            possession_s: (f.possession_s.iter().enumerate())
                .filter(|(_, s)| **s > 0.0)
                .map(|(i, s)| (by_robot(i), *s))
                .collect(),
            longest_dribble_mm: f.longest_dribble_mm,
            dribbled_too_far: f.dribbled_too_far,
            top_speed_mm_s: f.top_speed_mm_s,
            too_fast: f.too_fast,
            path_mm: f.path_mm,
            final_mm: [b.position_mm.x, b.position_mm.y],
        })
    }
}
