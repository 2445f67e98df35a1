//! A Small-Size striker on its own camera: it searches while no ball is known, goes round the
//! ball to stand behind it facing the goal, receives it on the spinning dribbler, turns with it
//! (never dribbling a metre, the rules' limit), aims at the part of the goal its free space
//! shows open and kicks; a rolling ball it meets on its predicted path, facing it. It never
//! enters a defense area: every command is cut where it would. With `task = "grab"` it stops
//! once it holds the ball (the vision-blackout challenge's first stage).
//!
//! It reads the ball from the `ball` stage ([`crate::perception::ball`]) and the free space
//! from `freespace` (for the open part of the goal); the field's figures come from the robot's
//! map. The behaviour is ours; the rules it keeps are the league's.

pub mod geometry;

use crate::ball_tracker::TrackerConfig;
use crate::boundary::{ActuatorCommand, ActuatorState, BodyCommand};
use crate::config::{FieldMap, RobotConfig};
use crate::controller::{
    ControlTable, Controller, ControllerEntry, Situation, check_table, settings,
};
use crate::perception::ball::BallEstimate;
use crate::perception::goal::GoalsSeen;
use geometry::{
    Approach, allowed_point, approach_direction, approach_point, intercept_point, keep_out,
    open_aim, unit, wrap,
};
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_problem::{Problem, Problems};
use omniloop_vision::FreeSpace;
use serde::{Deserialize, Serialize};

/// The registry's entry.
pub const ENTRY: ControllerEntry = ControllerEntry {
    name: "striker",
    summary: "a Small-Size striker on its own camera: search, go behind the ball, receive it on \
              the dribbler, aim at the open goal and kick, out of the defense areas",
    tables: &[ControlTable {
        name: TABLE,
        check: |spec| check_table(spec, TABLE, check_values),
    }],
    needs_goal: false,
    stages: &[
        crate::perception::ball::NAME,
        crate::perception::freespace::NAME,
        crate::perception::goal::NAME,
    ],
    check_use,
    build: |c| Ok(Box::new(Striker::new(c, settings(c, TABLE)?))),
};

/// Longest it moves onto the ball before it backs off to see it again, s.
const CAPTURE_S: f64 = 2.5;

/// How long it backs off, s.
const BACK_OFF_S: f64 = 1.0;

/// The least room it keeps from a defense area to reach a ball beside it, mm.
const CLOSEST_MM: f64 = 15.0;

/// Room kept between the body and the field walls, mm.
const WALL_ROOM_MM: f64 = 15.0;

/// How much farther than its margin from a defense area it waits while the ball lies inside.
const WAIT_ROOM_MM: f64 = 250.0;

/// Its settings table, `[control.striker]`.
const TABLE: &str = "striker";

/// What the striker is to do with the ball.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Task {
    /// Score in the goal it attacks.
    #[default]
    Score,
    /// Take the ball on the dribbler and stop there.
    Grab,
}

/// `[control.striker]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StrikerConfig {
    /// What to do with the ball.
    pub task: Task,
    /// The goal it attacks: `1` the one at +x, `-1` the one at -x.
    pub attack_side: f64,
    /// Top speed on the way, mm/s (at most the body's).
    pub speed_mm_s: f64,
    /// Speed onto the ball, mm/s.
    pub capture_speed_mm_s: f64,
    /// How far behind the ball it lines up before moving onto it, mm (E1's robot: the ball
    /// still in view there, just beyond the body's blind zone).
    pub standoff_mm: f64,
    /// The dribbler's speed near the ball, rpm.
    pub dribbler_rpm: f64,
    /// The kick's speed, mm/s (at most the kicker's).
    pub kick_speed_mm_s: f64,
    /// It kicks when aimed within this, degrees.
    pub aim_tolerance_deg: f64,
    /// Turn rate with the ball on the dribbler, rad/s.
    pub turn_with_ball_rad_s: f64,
    /// It releases the ball (kicks) after dribbling this far, mm (the rules allow 1 m).
    pub dribble_limit_mm: f64,
    /// Room kept from the defense areas beyond the body, mm.
    pub defense_margin_mm: f64,
    /// Where to look for the ball while none is known, world frame (default: the field's
    /// centre and the centres of its four quarters).
    pub search_points_mm: Vec<[f64; 2]>,
}

impl Default for StrikerConfig {
    fn default() -> Self {
        Self {
            task: Task::Score,
            attack_side: 1.0,
            speed_mm_s: 1500.0,
            capture_speed_mm_s: 350.0,
            standoff_mm: 260.0,
            dribbler_rpm: 5000.0,
            kick_speed_mm_s: 5000.0,
            aim_tolerance_deg: 2.0,
            turn_with_ball_rad_s: 1.5,
            dribble_limit_mm: 800.0,
            defense_margin_mm: 60.0,
            search_points_mm: Vec::new(),
        }
    }
}

/// `[control.striker]`'s values.
fn check_values(c: &StrikerConfig, p: &mut Problems) {
    if c.attack_side != 1.0 && c.attack_side != -1.0 {
        p.fail(
            "attack_side",
            format!("must be 1 or -1 (got {})", c.attack_side),
        );
    }
    for (name, v) in [
        ("speed_mm_s", c.speed_mm_s),
        ("capture_speed_mm_s", c.capture_speed_mm_s),
        ("standoff_mm", c.standoff_mm),
        ("kick_speed_mm_s", c.kick_speed_mm_s),
        ("aim_tolerance_deg", c.aim_tolerance_deg),
        ("turn_with_ball_rad_s", c.turn_with_ball_rad_s),
        ("dribble_limit_mm", c.dribble_limit_mm),
    ] {
        p.positive(name, v);
    }
    p.non_negative("dribbler_rpm", c.dribbler_rpm);
    p.non_negative("defense_margin_mm", c.defense_margin_mm);
}

/// What the striker needs of the robot: a kicker and the field on its map.
fn check_use(c: &RobotConfig) -> Vec<Problem> {
    let mut out = Vec::new();
    if c.body.kicker.is_none() {
        out.push(Problem::new(
            "robot.kicker",
            "the striker needs a kicker: add [robot.kicker]",
        ));
    }
    if c.map.field.is_none() {
        out.push(Problem::new(
            "world.field",
            "the striker plays on a field: add [world.field]",
        ));
    }
    out
}

/// The striker.
pub struct Striker {
    config: StrikerConfig,
    field: Option<FieldMap>,
    radius_mm: f64,
    front_mm: f64,
    max_speed_mm_s: f64,
    accel_mm_s2: f64,
    ball_radius_mm: f64,
    /// Within this distance the body hides the ball: it goes round the ball beyond it.
    blind_radius_mm: f64,
    roll_decel_mm_s2: f64,
    /// Where (odometry frame) the ball was taken onto the dribbler.
    captured_at: Option<Point2<f64>>,
    /// The search point it is heading for.
    search: usize,
    /// The point of the goal it aims at, once it holds the ball.
    aim: Option<Point2<f64>>,
    /// Since when it has been moving onto the ball, s.
    capture_since_s: Option<f64>,
    /// Until when it backs off from a capture that went wrong, s.
    back_off_until_s: f64,
    /// Room it keeps from the defense areas beyond the body this cycle, mm: the configured
    /// margin, less where a ball by an area can only be reached so.
    margin_mm: f64,
    /// Its velocity this cycle as odometry measures it, body frame, mm/s.
    velocity_mm_s: Vector2<f64>,
    /// The direction it is taking the ball in (world frame), while it goes for it.
    approach: Option<Approach>,
    /// The actuator commands of this cycle.
    commands: Vec<ActuatorCommand>,
}

impl Striker {
    /// The striker for a robot.
    pub fn new(c: &RobotConfig, config: StrikerConfig) -> Self {
        let ball: crate::perception::ball::BallSettings =
            c.vision.table("ball").unwrap_or_default();
        let kick = c.body.kicker.map_or(0.0, |k| k.max_kick_mm_s);
        Self {
            config: StrikerConfig {
                kick_speed_mm_s: config.kick_speed_mm_s.min(kick),
                ..config
            },
            field: c.map.field,
            radius_mm: c.body.radius_mm,
            front_mm: c.body.kicker.map_or(c.body.radius_mm, |k| k.front_mm),
            max_speed_mm_s: c.body.max_speed_mm_s,
            accel_mm_s2: c.body.accel_limit_mm_s2,
            ball_radius_mm: ball.radius_mm,
            blind_radius_mm: ball.blind_radius_mm,
            roll_decel_mm_s2: TrackerConfig::default().roll_decel_mm_s2,
            captured_at: None,
            search: 0,
            aim: None,
            capture_since_s: None,
            back_off_until_s: f64::NEG_INFINITY,
            margin_mm: config.defense_margin_mm,
            velocity_mm_s: Vector2::zeros(),
            approach: None,
            commands: Vec::new(),
        }
    }

    /// The search points: the configured ones, or the field's centre and quarters.
    fn search_points(&self) -> Vec<Point2<f64>> {
        if !self.config.search_points_mm.is_empty() {
            return self
                .config
                .search_points_mm
                .iter()
                .map(|p| Point2::new(p[0], p[1]))
                .collect();
        }
        let f = self.field.as_ref();
        let (hx, hy) = f.map_or((1000.0, 1000.0), |f| {
            (0.5 * f.half_length_mm, 0.5 * f.half_width_mm)
        });
        let side = self.config.attack_side;
        vec![
            Point2::new(0.0, 0.0),
            Point2::new(-side * hx, hy),
            Point2::new(side * hx, hy),
            Point2::new(side * hx, -hy),
            Point2::new(-side * hx, -hy),
        ]
    }

    /// The command that takes the robot at `pose` to `target` facing `heading`, slowing to stop
    /// there, kept out of the defense areas.
    fn go(
        &self,
        pose: &Isometry2<f64>,
        target: Point2<f64>,
        heading: f64,
        top: f64,
    ) -> BodyCommand {
        let here = Point2::from(pose.translation.vector);
        let target = match &self.field {
            Some(f) => allowed_point(
                f,
                target,
                self.radius_mm + self.margin_mm,
                self.radius_mm + WALL_ROOM_MM,
            ),
            None => target,
        };
        let d = target - here;
        let speed = top
            .min(self.max_speed_mm_s)
            .min((2.0 * 0.8 * self.accel_mm_s2 * d.norm()).sqrt())
            .min(4.0 * d.norm());
        let v = pose.rotation.inverse() * (unit(d) * speed);
        let err = wrap(heading - pose.rotation.angle());
        BodyCommand {
            v_mm_s: self.kept_out(pose, v),
            omega_rad_s: (4.0 * err).clamp(-4.0, 4.0),
        }
    }

    /// `v` (body frame) kept out of the defense areas (see [`keep_out`]).
    fn kept_out(&self, pose: &Isometry2<f64>, v: Vector2<f64>) -> Vector2<f64> {
        let Some(f) = &self.field else {
            return v;
        };
        let here = Point2::from(pose.translation.vector);
        let world = keep_out(
            f,
            here,
            [pose.rotation * v, pose.rotation * self.velocity_mm_s],
            self.radius_mm,
            self.margin_mm,
            self.accel_mm_s2,
        );
        pose.rotation.inverse() * world
    }

    /// With the ball on the dribbler: stop (grab), or turn to the open goal and kick.
    fn with_ball(&mut self, s: &Situation<'_>, pose: &Isometry2<f64>) -> BodyCommand {
        let at = *self
            .captured_at
            .get_or_insert(Point2::from(s.odometry_pose.translation.vector));
        self.commands.push(ActuatorCommand::Dribble {
            rpm: self.config.dribbler_rpm,
        });
        // Slow down gently: a sudden stop pulls the ball off the dribbler.
        let v = s.velocity_body_mm_s;
        let slowed = self.kept_out(
            pose,
            v * (1.0 - 1000.0 * 0.05 / v.norm().max(1e-9)).max(0.0),
        );
        if self.config.task == Task::Grab {
            return BodyCommand::translate(slowed);
        }
        let Some(f) = self.field else {
            return BodyCommand::STOP;
        };
        let ball = pose * Point2::new(self.front_mm + self.ball_radius_mm, 0.0);
        let obstacles: Vec<Point2<f64>> = s
            .percept::<FreeSpace>()
            .map(|fs| fs.obstacle_points.iter().map(|p| pose * p).collect())
            .unwrap_or_default();
        let goal = f.goal_centre(self.config.attack_side);
        let aim = open_aim(
            goal,
            f.goal_width_mm,
            ball,
            self.ball_radius_mm,
            &obstacles,
            self.aim,
        );
        self.aim = Some(aim);
        // The goal the camera shows, where it shows it: the middle of its widest open part;
        // else where the map and the pose estimate put the open part.
        let seen = s
            .percept::<GoalsSeen>()
            .and_then(|g| g.of(self.config.attack_side).first().copied());
        let to = pose.inverse() * aim;
        let (err, tol) = match seen {
            Some(run) => (
                wrap(run.centre_rad),
                (0.3 * run.width_rad).clamp(
                    0.5f64.to_radians(),
                    self.config.aim_tolerance_deg.to_radians(),
                ),
            ),
            None => (to.y.atan2(to.x), self.config.aim_tolerance_deg.to_radians()),
        };
        let dribbled = (Point2::from(s.odometry_pose.translation.vector) - at).norm();
        if err.abs() < tol || dribbled > self.config.dribble_limit_mm {
            self.commands.push(ActuatorCommand::Kick {
                speed_mm_s: self.config.kick_speed_mm_s,
                angle_rad: 0.0,
            });
        }
        let rate = self.config.turn_with_ball_rad_s;
        BodyCommand {
            v_mm_s: slowed,
            omega_rad_s: (3.0 * err).clamp(-rate, rate),
        }
    }

    /// With the ball known and not held: meet it if it rolls, else go behind it and onto it.
    fn chase(&mut self, pose: &Isometry2<f64>, ball: &BallEstimate, t_s: f64) -> BodyCommand {
        let here = Point2::from(pose.translation.vector);
        let b = pose * ball.body_mm;
        let v = pose.rotation * ball.velocity_body_mm_s;
        let contact = self.front_mm + self.ball_radius_mm;
        if ball.body_mm.coords.norm() < contact + 600.0 {
            self.commands.push(ActuatorCommand::Dribble {
                rpm: self.config.dribbler_rpm,
            });
        }
        // Wholly inside a defense area: out of reach by the rules.
        let r = self.ball_radius_mm;
        if let Some(f) = self.field.filter(|f| f.in_defense_area(b, -r)) {
            return self.wait_outside(pose, &f, b);
        }
        if v.norm() > 500.0 && v.dot(&(here - b)) > 0.0 {
            return self.meet(pose, b, v);
        }
        let Some(approach) = self.approach_to(here, b) else {
            return match &self.field {
                Some(f) => self.wait_outside(pose, f, b),
                None => BodyCommand::STOP,
            };
        };
        self.approach = Some(approach);
        self.margin_mm = approach.margin_mm - self.radius_mm;
        let (toward, standoff) = (approach.toward, approach.standoff_mm);
        let heading = toward.y.atan2(toward.x);
        let behind = b - toward * standoff;
        let lined_up = (here - behind).norm() < 60.0 || {
            let r = here - b;
            let across = (r - toward * r.dot(&toward)).norm();
            let along = r.dot(&-toward);
            along > contact && along < standoff + 60.0 && across < 25.0
        };
        let facing = wrap(heading - pose.rotation.angle()).abs() < 10f64.to_radians();
        // A capture that has not taken the ball in CAPTURE_S went wrong (the ball, hidden by the
        // body, is not where the tracker holds it): back off to see it again.
        if t_s < self.back_off_until_s {
            self.capture_since_s = None;
            let back = b - toward * (self.blind_radius_mm + 100.0);
            return self.go(pose, back, heading, self.config.capture_speed_mm_s);
        }
        if lined_up && facing {
            let since = *self.capture_since_s.get_or_insert(t_s);
            if t_s - since > CAPTURE_S {
                self.back_off_until_s = t_s + BACK_OFF_S;
            }
            return self.go(
                pose,
                b - toward * (contact - 15.0),
                heading,
                self.config.capture_speed_mm_s,
            );
        }
        self.capture_since_s = None;
        let clear = (self.radius_mm + self.ball_radius_mm + 80.0).max(self.blind_radius_mm + 60.0);
        let next = approach_point(here, b, toward, standoff, clear);
        self.go(pose, next, heading, self.config.speed_mm_s)
    }

    /// A ball rolling at `v` toward the robot, met on its predicted path facing it.
    fn meet(&self, pose: &Isometry2<f64>, b: Point2<f64>, v: Vector2<f64>) -> BodyCommand {
        let here = Point2::from(pose.translation.vector);
        let meet = intercept_point(
            here,
            b,
            v,
            self.roll_decel_mm_s2,
            0.7 * self.max_speed_mm_s,
            0.3,
        );
        let face = -unit(v);
        let contact = self.front_mm + self.ball_radius_mm;
        self.go(
            pose,
            meet - face * contact,
            face.y.atan2(face.x),
            self.config.speed_mm_s,
        )
    }

    /// How to take the ball at `b` from `here`: from behind it facing the goal (grab: facing
    /// it), or, where that side is out of bounds (a ball by a defense area or a line), from
    /// another side, turning with it after; `None` for a ball by a defense area that cannot
    /// be reached from outside it.
    fn approach_to(&self, here: Point2<f64>, b: Point2<f64>) -> Option<Approach> {
        let contact = self.front_mm + self.ball_radius_mm;
        let preferred = match (self.config.task, &self.field) {
            (Task::Score, Some(f)) => unit(f.goal_centre(self.config.attack_side) - b),
            _ => unit(b - here),
        };
        let full = Approach {
            toward: preferred,
            standoff_mm: contact + self.config.standoff_mm,
            margin_mm: self.radius_mm + self.config.defense_margin_mm,
        };
        let Some(f) = &self.field else {
            return Some(full);
        };
        let found = approach_direction(
            f,
            b,
            here,
            preferred,
            self.approach,
            [contact - 15.0, full.standoff_mm],
            [full.margin_mm, self.radius_mm + CLOSEST_MM],
            self.radius_mm + WALL_ROOM_MM,
        );
        match found {
            None if f.in_defense_area(b, full.margin_mm) => None,
            None => Some(full),
            a => a,
        }
    }

    /// With the ball out of reach in a defense area: wait facing it, well outside (standing at
    /// the margin, the pose estimate's error would carry the body over the line in time).
    fn wait_outside(&self, pose: &Isometry2<f64>, f: &FieldMap, b: Point2<f64>) -> BodyCommand {
        let here = Point2::from(pose.translation.vector);
        let heading = unit(b - here);
        let wait = allowed_point(
            f,
            b,
            self.radius_mm + self.config.defense_margin_mm + WAIT_ROOM_MM,
            self.radius_mm + WALL_ROOM_MM,
        );
        self.go(
            pose,
            wait,
            heading.y.atan2(heading.x),
            self.config.speed_mm_s,
        )
    }

    /// With no ball known: the search points in turn.
    fn searching(&mut self, pose: &Isometry2<f64>) -> BodyCommand {
        let points = self.search_points();
        let here = Point2::from(pose.translation.vector);
        if (points[self.search % points.len()] - here).norm() < 150.0 {
            self.search += 1;
        }
        let target = points[self.search % points.len()];
        // Turn slowly while searching: the body hides part of the floor behind the kicker.
        let heading = pose.rotation.angle() + 0.5;
        self.go(pose, target, heading, self.config.speed_mm_s)
    }
}

impl Controller for Striker {
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand {
        self.commands.clear();
        self.velocity_mm_s = s.velocity_body_mm_s;
        self.margin_mm = self.config.defense_margin_mm;
        let Some(pose) = s.pose else {
            return BodyCommand::STOP;
        };
        let held = s.actuators.iter().any(|a| {
            matches!(
                a,
                ActuatorState::Kicker {
                    ball_in_dribbler: true,
                    ..
                }
            )
        });
        if held {
            return self.with_ball(s, &pose);
        }
        self.captured_at = None;
        self.aim = None;
        if s.percept::<BallEstimate>().is_none() {
            self.approach = None;
        }
        match s.percept::<BallEstimate>() {
            Some(ball) => self.chase(&pose, ball, s.t_s),
            None => self.searching(&pose),
        }
    }

    fn actuators(&mut self) -> Vec<ActuatorCommand> {
        let mut out = std::mem::take(&mut self.commands);
        if !out
            .iter()
            .any(|c| matches!(c, ActuatorCommand::Dribble { .. }))
        {
            out.push(ActuatorCommand::Dribble { rpm: 0.0 });
        }
        out
    }
}
