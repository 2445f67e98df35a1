//! The physics world: rapier2d bodies for the field, walls, cubes, pillars and the robots.
//!
//! Robots are dynamic discs whose velocity is set every physics step by the drive model of
//! eq. (8) ([`AccelLimitedDrive`]), starting from the velocity the body actually has, so that a
//! robot pushed back by a wall accelerates again at the limit. A differential-drive robot
//! ([`DifferentialDrive`]) moves only along its heading: at every step its velocity is set
//! along its current heading from its forward speed, so it never slides sideways. Obstacles are fixed colliders, so
//! a robot never passes through them, whatever it is commanded. Contacts are counted from the
//! engine's collision events, confirmed by the contact manifold's distance (rapier also reports
//! speculative contacts a few millimetres before touching).

mod play;

use crate::SimError;
use crate::ball::{BallSpec, BallState};
use crate::color::Rgb;
use crate::game::{BallEvent, BallFigures, Referee};
use crate::kicker::{BallCommand, KickerSpec};
use crate::labels::{Class, ObjectId};
use crate::layout::Layout;
use crate::shapes::{Solid, SolidShape};
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_control::{AccelLimitedDrive, DifferentialDrive, VelocityCommand};
use rapier2d::prelude::*;
use std::sync::mpsc::{Receiver, channel};

/// Two colliders closer than this (mm) are touching.
pub const TOUCH_TOLERANCE_MM: f64 = 0.5;

/// A robot body: a disc, omnidirectional unless it has a differential drive.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotBodySpec {
    /// Pose at the start: x, y in mm, rotation in rad.
    pub start: Isometry2<f64>,
    /// Disc radius.
    pub radius_mm: f64,
    /// Body height (for rendering).
    pub height_mm: f64,
    /// Translational acceleration limit alpha of eq. (8).
    pub accel_limit_mm_s2: f64,
    /// Rotational acceleration limit.
    pub angular_accel_limit_rad_s2: f64,
    /// Top speed: a command faster than this is scaled down to it by its norm, whoever gave it.
    pub max_speed_mm_s: f64,
    /// Body colour (for rendering).
    pub rgb: Rgb,
    /// Colour of its top face, a team's marking that other robots' cameras see (for
    /// rendering; the body colour when `None`).
    pub marking_rgb: Option<Rgb>,
    /// Its drive when it is a differential-drive robot (then it takes the forward part of its
    /// commands and their rotation rate; the acceleration limits above are not used).
    pub differential: Option<DifferentialDrive>,
    /// Its kicker and dribbler, on a flat front, when it has them.
    pub kicker: Option<KickerSpec>,
}

/// The state of a robot as the physics engine has it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobotState {
    /// Position (mm) and heading (rad).
    pub pose: Isometry2<f64>,
    /// Velocity in the world frame.
    pub velocity_mm_s: Vector2<f64>,
    /// Rotation rate.
    pub omega_rad_s: f64,
}

/// Touches counted by the class of what was touched.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ContactsByClass([u32; Class::ALL.len()]);

impl ContactsByClass {
    /// One more touch of a thing of `class`.
    fn add(&mut self, class: Class) {
        self.0[class as usize] += 1;
    }

    /// How many touches of things of `class`.
    pub fn of(&self, class: Class) -> u32 {
        self.0[class as usize]
    }

    /// The classes touched at least once, with their counts, in the classes' order.
    pub fn touched(&self) -> impl Iterator<Item = (Class, u32)> + '_ {
        Class::ALL
            .iter()
            .map(|&c| (c, self.of(c)))
            .filter(|(_, n)| *n > 0)
    }
}

/// What happened to a robot so far, measured at every physics step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobotStats {
    /// How many times it started touching a wall, cube, pillar or robot.
    pub contacts: u32,
    /// Of those, how many were with a wall, cube, pillar or board.
    pub solid_contacts: u32,
    /// Of those, how many were with another robot.
    pub robot_contacts: u32,
    /// All of them by the class of what was touched (from the touched collider's own object).
    pub contacts_by_class: ContactsByClass,
    /// Largest |dv| / dt between two physics steps.
    pub peak_accel_mm_s2: f64,
    /// Largest speed.
    pub peak_speed_mm_s: f64,
    /// Smallest distance from its edge to a solid or another robot.
    pub min_clearance_mm: f64,
    /// Smallest distance from its edge to another robot's edge (infinite alone).
    pub min_robot_clearance_mm: f64,
    /// Length of the path its centre travelled.
    pub path_length_mm: f64,
}

impl RobotStats {
    fn new() -> Self {
        Self {
            contacts: 0,
            solid_contacts: 0,
            robot_contacts: 0,
            contacts_by_class: ContactsByClass::default(),
            peak_accel_mm_s2: 0.0,
            peak_speed_mm_s: 0.0,
            min_clearance_mm: f64::INFINITY,
            min_robot_clearance_mm: f64::INFINITY,
            path_length_mm: 0.0,
        }
    }
}

struct Robot {
    spec: RobotBodySpec,
    body: RigidBodyHandle,
    collider: ColliderHandle,
    drive: AccelLimitedDrive,
    /// The command: in the world frame, or for a differential robot (forward speed, 0) in its
    /// body frame.
    command: VelocityCommand,
    stats: RobotStats,
    /// Colliders rapier says this robot is in contact with, and whether they actually touch.
    pairs: Vec<(ColliderHandle, bool)>,
    /// What it commands its kicker and dribbler.
    ball_command: BallCommand,
    /// When its kicker is charged again.
    kicker_ready_at_s: f64,
}

/// What a collider belongs to, kept in its `user_data`: the collider itself says what was
/// touched.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Owner {
    Solid(usize),
    Robot(usize),
}

impl Owner {
    const SOLID: u128 = 1 << 64;
    const ROBOT: u128 = 2 << 64;

    /// The collider's `user_data` that names this owner.
    fn user_data(self) -> u128 {
        match self {
            Owner::Solid(k) => Self::SOLID | k as u128,
            Owner::Robot(i) => Self::ROBOT | i as u128,
        }
    }

    /// The owner a collider's `user_data` names.
    fn of(user_data: u128) -> Option<Self> {
        let index = (user_data & u128::from(u64::MAX)) as usize;
        match user_data & !u128::from(u64::MAX) {
            Self::SOLID => Some(Owner::Solid(index)),
            Self::ROBOT => Some(Owner::Robot(index)),
            _ => None,
        }
    }
}

/// The simulated world.
pub struct World {
    physics: PhysicsWorld,
    layout: Layout,
    solids: Vec<Solid>,
    /// Each solid's bounding circle (centre, radius in mm), which spares the clearance most
    /// distances.
    solid_bounds: Vec<(Point2<f64>, f64)>,
    robots: Vec<Robot>,
    events: ChannelEventCollector,
    collisions: Receiver<CollisionEvent>,
    _forces: Receiver<ContactForceEvent>,
    _tears: Receiver<SoftBodyTearEvent>,
    physics_step_s: f64,
    steps: u64,
    /// Touches between two robots (their indices, the lower first), each once.
    robot_touches: Vec<(usize, usize)>,
    /// The ball, when there is one.
    play: Option<play::Play>,
}

fn vec(v: Vector2<f64>) -> Vector {
    Vector::new(v.x as Real, v.y as Real)
}

/// The collider of a solid's footprint.
fn solid_collider(shape: &SolidShape) -> Result<ColliderBuilder, SimError> {
    Ok(match *shape {
        SolidShape::Box {
            center_mm,
            half_extents_mm,
            angle_rad,
        } => ColliderBuilder::cuboid(half_extents_mm.x as Real, half_extents_mm.y as Real)
            .translation(vec(center_mm.coords))
            .rotation(angle_rad as Real),
        SolidShape::Cylinder {
            center_mm,
            radius_mm,
        } => ColliderBuilder::ball(radius_mm as Real).translation(vec(center_mm.coords)),
        SolidShape::Quad { corners_mm } => {
            let points: Vec<Vector> = corners_mm.iter().map(|c| vec(c.coords)).collect();
            ColliderBuilder::convex_hull(&points)
                .ok_or_else(|| SimError::Invalid(format!("degenerate wall piece {corners_mm:?}")))?
        }
    })
}

impl World {
    /// Builds the world from its layout and robots, stepping physics every `physics_step_s`.
    pub fn new(
        layout: &Layout,
        robots: &[RobotBodySpec],
        physics_step_s: f64,
    ) -> Result<Self, SimError> {
        if !(physics_step_s.is_finite() && physics_step_s > 0.0) {
            return Err(SimError::Invalid(format!(
                "physics_step_s = {physics_step_s} must be > 0"
            )));
        }
        let mut physics = PhysicsWorld::new();
        physics.gravity = Vector::ZERO;
        physics.integration_parameters.dt = physics_step_s as Real;
        physics.integration_parameters.length_unit = 1000.0;

        let solids = layout.solids();
        for (k, s) in solids.iter().enumerate() {
            let collider = solid_collider(&s.shape)?
                .friction(0.0)
                .restitution(0.0)
                .user_data(Owner::Solid(k).user_data());
            physics.insert_collider(collider, None);
        }

        let mut out = Vec::with_capacity(robots.len());
        for spec in robots {
            let drive =
                AccelLimitedDrive::new(spec.accel_limit_mm_s2, spec.angular_accel_limit_rad_s2)
                    .map_err(|e| SimError::Invalid(e.to_string()))?;
            let body = RigidBodyBuilder::dynamic()
                .translation(vec(spec.start.translation.vector))
                .rotation(spec.start.rotation.angle() as Real)
                .ccd_enabled(true)
                .can_sleep(false);
            let collider = ColliderBuilder::ball(spec.radius_mm as Real)
                .friction(0.0)
                .restitution(0.0)
                .active_events(ActiveEvents::COLLISION_EVENTS)
                .user_data(Owner::Robot(out.len()).user_data());
            let (body, collider) = physics.insert(body, collider);
            out.push(Robot {
                spec: spec.clone(),
                body,
                collider,
                drive,
                command: VelocityCommand::STOP,
                stats: RobotStats::new(),
                pairs: Vec::new(),
                ball_command: BallCommand::default(),
                kicker_ready_at_s: 0.0,
            });
        }
        let (ctx, crx) = channel();
        let (ftx, frx) = channel();
        let (ttx, trx) = channel();
        Ok(Self {
            physics,
            layout: layout.clone(),
            solid_bounds: solids.iter().map(|s| s.shape.bounding_circle()).collect(),
            solids,
            robots: out,
            events: ChannelEventCollector::new(ctx, ftx, ttx),
            collisions: crx,
            _forces: frx,
            _tears: trx,
            physics_step_s,
            steps: 0,
            robot_touches: Vec::new(),
            play: layout.ball.as_ref().map(|b| {
                let referee = Referee::new(layout.field.clone(), robots.len());
                play::Play::new(b, robots.len(), referee)
            }),
        })
    }

    /// The static layout.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The static solids (walls, cubes, pillars) in world coordinates.
    pub fn solids(&self) -> &[Solid] {
        &self.solids
    }

    /// Simulated time since the start.
    pub fn time_s(&self) -> f64 {
        self.steps as f64 * self.physics_step_s
    }

    /// Sets the velocity command (world frame) robot `i` follows (through its drive) from now
    /// on, scaled down by its norm to the robot's top speed where it is faster. A differential
    /// robot keeps the part along its present heading: it cannot move sideways.
    pub fn set_command(&mut self, i: usize, mut command: VelocityCommand) {
        let heading = self.robot_state(i).pose.rotation;
        let r = &mut self.robots[i];
        // Over by more than rounding (a controller's command at the top speed may come out a
        // bit above it): scaled down.
        let speed = command.v_mm_s.norm();
        if speed > r.spec.max_speed_mm_s * (1.0 + 1e-9) {
            command.v_mm_s *= r.spec.max_speed_mm_s / speed;
        }
        r.command = match r.spec.differential {
            None => command,
            Some(_) => VelocityCommand {
                v_mm_s: Vector2::new((heading.inverse() * command.v_mm_s).x, 0.0),
                omega_rad_s: command.omega_rad_s,
            },
        };
    }

    /// The command robot `i` follows (world frame).
    pub fn command(&self, i: usize) -> VelocityCommand {
        let r = &self.robots[i];
        match r.spec.differential {
            None => r.command,
            Some(_) => VelocityCommand {
                v_mm_s: self.robot_state(i).pose.rotation * r.command.v_mm_s,
                omega_rad_s: r.command.omega_rad_s,
            },
        }
    }

    /// Puts robot `i` at `pose`, at rest, with its command cleared (an experimenter carrying
    /// the robot to a place). Contacts and statistics carry on.
    pub fn place_robot(&mut self, i: usize, pose: Isometry2<f64>) {
        let r = &mut self.robots[i];
        r.command = VelocityCommand::STOP;
        let body = &mut self.physics.bodies[r.body];
        body.set_position(
            Pose::new(vec(pose.translation.vector), pose.rotation.angle() as Real),
            true,
        );
        body.set_linvel(Vector::ZERO, true);
        body.set_angvel(0.0, true);
    }

    /// Position, heading and velocity of robot `i`.
    pub fn robot_state(&self, i: usize) -> RobotState {
        let body = &self.physics.bodies[self.robots[i].body];
        let t = body.translation();
        let v = body.linvel();
        RobotState {
            pose: Isometry2::new(
                Vector2::new(t.x as f64, t.y as f64),
                body.rotation().angle() as f64,
            ),
            velocity_mm_s: Vector2::new(v.x as f64, v.y as f64),
            omega_rad_s: body.angvel() as f64,
        }
    }

    /// Contacts, peak speed and acceleration, clearance and path length of robot `i`.
    pub fn stats(&self, i: usize) -> RobotStats {
        self.robots[i].stats
    }

    /// Every time two robots started touching, once each: the two robots' indices, the
    /// lower first.
    pub fn robot_touches(&self) -> &[(usize, usize)] {
        &self.robot_touches
    }

    /// Distance from robot `i`'s edge to the nearest solid or other robot.
    pub fn clearance_mm(&self, i: usize) -> f64 {
        let (solids, robots) = self.clearances_mm(i);
        solids.min(robots)
    }

    /// Distances from robot `i`'s edge to the nearest solid and to the nearest other robot's
    /// edge (infinite where there is none).
    fn clearances_mm(&self, i: usize) -> (f64, f64) {
        let me = self.robot_state(i);
        let p = Point2::from(me.pose.translation.vector);
        let r = self.robots[i].spec.radius_mm;
        let mut solids = f64::INFINITY;
        for (s, (centre, radius)) in self.solids.iter().zip(&self.solid_bounds) {
            // A solid is no nearer than its bounding circle: one that cannot be nearer than
            // the nearest so far (with a micrometre for rounding) leaves the minimum as it is.
            if (p - centre).norm() - radius - r - 1e-3 > solids {
                continue;
            }
            solids = solids.min(s.shape.distance_mm(p) - r);
        }
        let mut robots = f64::INFINITY;
        for (j, other) in self.robots.iter().enumerate() {
            if j != i {
                let q = self.robot_state(j).pose.translation.vector;
                robots = robots.min((q - p.coords).norm() - other.spec.radius_mm - r);
            }
        }
        (solids, robots)
    }

    /// What collider `h` belongs to, as its `user_data` says.
    fn owner(&self, h: ColliderHandle) -> Option<Owner> {
        self.physics
            .colliders
            .get(h)
            .and_then(|c| Owner::of(c.user_data))
    }

    /// The thing an owner of a collider is.
    fn object(&self, owner: Owner) -> ObjectId {
        match owner {
            Owner::Solid(k) => self.solids[k].object,
            Owner::Robot(j) => ObjectId::new(Class::Robot, j as u32),
        }
    }

    /// Gap between robot `i`'s disc and the collider `other`.
    fn gap_mm(&self, i: usize, other: ColliderHandle) -> f64 {
        let p = Point2::from(self.robot_state(i).pose.translation.vector);
        let r = self.robots[i].spec.radius_mm;
        match self.owner(other) {
            Some(Owner::Solid(k)) => self.solids[k].shape.distance_mm(p) - r,
            Some(Owner::Robot(j)) => {
                let q = self.robot_state(j).pose.translation.vector;
                (q - p.coords).norm() - r - self.robots[j].spec.radius_mm
            }
            None => f64::INFINITY,
        }
    }

    /// The solid footprints of every robot except `except`, for ray casts and rendering.
    pub fn robot_solids(&self, except: Option<usize>) -> Vec<Solid> {
        (0..self.robots.len())
            .filter(|&j| Some(j) != except)
            .map(|j| {
                let spec = &self.robots[j].spec;
                Solid::standing(
                    SolidShape::Cylinder {
                        center_mm: Point2::from(self.robot_state(j).pose.translation.vector),
                        radius_mm: spec.radius_mm,
                    },
                    spec.height_mm,
                    spec.rgb,
                )
                .with_top(spec.marking_rgb)
                .as_object(ObjectId::new(Class::Robot, j as u32))
            })
            .collect()
    }

    /// Distance from `origin` along unit `dir` to the first solid or robot other than `except`
    /// (the ground truth for free space), or `None` beyond `max_mm`.
    pub fn ray_cast_mm(
        &self,
        origin: Point2<f64>,
        dir: Vector2<f64>,
        max_mm: f64,
        except: Option<usize>,
    ) -> Option<f64> {
        let robots = self.robot_solids(except);
        let bounded = (self.solids.iter().zip(self.solid_bounds.iter().copied()))
            .chain(robots.iter().map(|s| (s, s.shape.bounding_circle())));
        // A solid whose bounding circle the ray misses within `max_mm` is not cast against.
        bounded
            .filter(|(_, bounds)| SolidShape::ray_may_meet(*bounds, origin, dir, max_mm))
            .filter_map(|(s, _)| s.shape.ray_cast_mm(origin, dir, max_mm))
            .min_by(f64::total_cmp)
    }

    /// Advances the world by `duration_s` in physics steps (rounded to a whole number of
    /// steps), applying each robot's command through its drive at every step.
    pub fn advance(&mut self, duration_s: f64) {
        let n = (duration_s / self.physics_step_s).round().max(1.0) as u64;
        for _ in 0..n {
            self.step();
        }
    }

    fn step(&mut self) {
        let dt = self.physics_step_s;
        let mut before = Vec::with_capacity(self.robots.len());
        for r in &self.robots {
            let body = &mut self.physics.bodies[r.body];
            let v = body.linvel();
            let v = Vector2::new(v.x as f64, v.y as f64);
            let (v_new, w_new) = match &r.spec.differential {
                None => (
                    r.drive.step(v, r.command.v_mm_s, dt),
                    r.drive
                        .step_angular(body.angvel() as f64, r.command.omega_rad_s, dt),
                ),
                Some(d) => {
                    let a = body.rotation().angle() as f64;
                    let along = Vector2::new(a.cos(), a.sin());
                    let (s, w) = d.step(
                        v.dot(&along),
                        body.angvel() as f64,
                        (r.command.v_mm_s.x, r.command.omega_rad_s),
                        dt,
                    );
                    (along * s, w)
                }
            };
            body.set_linvel(vec(v_new), true);
            body.set_angvel(w_new as Real, true);
            let t = body.translation();
            before.push((v, Vector2::new(t.x as f64, t.y as f64)));
        }
        self.physics.step_with_events(&(), &self.events);
        self.steps += 1;

        for (i, (v0, p0)) in before.into_iter().enumerate() {
            let s = self.robot_state(i);
            let (to_solids, to_robots) = self.clearances_mm(i);
            let st = &mut self.robots[i].stats;
            let a = (s.velocity_mm_s - v0).norm() / dt;
            st.peak_accel_mm_s2 = st.peak_accel_mm_s2.max(a);
            st.peak_speed_mm_s = st.peak_speed_mm_s.max(s.velocity_mm_s.norm());
            st.path_length_mm += (s.pose.translation.vector - p0).norm();
            st.min_clearance_mm = st.min_clearance_mm.min(to_solids.min(to_robots));
            st.min_robot_clearance_mm = st.min_robot_clearance_mm.min(to_robots);
        }
        while let Ok(event) = self.collisions.try_recv() {
            let (c1, c2, started) = match event {
                CollisionEvent::Started(a, b, _) => (a, b, true),
                CollisionEvent::Stopped(a, b, _) => (a, b, false),
            };
            for r in self.robots.iter_mut() {
                let other = if r.collider == c1 {
                    c2
                } else if r.collider == c2 {
                    c1
                } else {
                    continue;
                };
                if started {
                    if !r.pairs.iter().any(|(h, _)| *h == other) {
                        r.pairs.push((other, false));
                    }
                } else {
                    r.pairs.retain(|(h, _)| *h != other);
                }
            }
        }
        self.confirm_contacts();
        self.step_ball(dt);
    }

    /// The ball's physics step, the robots moved; a robot that kicked recharges.
    fn step_ball(&mut self, dt: f64) {
        if self.play.is_none() {
            return;
        }
        let t = self.time_s();
        let bodies = self.ball_bodies();
        let kicked = match &mut self.play {
            Some(play) => play.step(t, dt, &self.solids, &bodies),
            None => Vec::new(),
        };
        for j in kicked {
            let r = &mut self.robots[j];
            r.ball_command.kick = None;
            r.kicker_ready_at_s = t + r.spec.kicker.as_ref().map_or(0.0, |k| k.recharge_s);
        }
    }

    /// Robot `i` commands its kicker and dribbler: the dribbler's speed from now on; a kick,
    /// when given, armed until it fires (a kick of speed 0 disarms). A robot without a kicker
    /// ignores it.
    pub fn set_ball_command(&mut self, i: usize, command: BallCommand) {
        let c = &mut self.robots[i].ball_command;
        c.dribbler_rpm = command.dribbler_rpm;
        if let Some(k) = command.kick {
            c.kick = (k.speed_mm_s > 0.0).then_some(k);
        }
    }

    /// Whether robot `i`'s light barrier sees the ball now (false without a kicker or ball).
    pub fn light_barrier(&self, i: usize) -> bool {
        let Some(play) = &self.play else {
            return false;
        };
        if play.holder() == Some(i) {
            return true;
        }
        let (Some(k), s) = (&self.robots[i].spec.kicker, self.robot_state(i)) else {
            return false;
        };
        let local = s.pose.inverse_transform_point(&play.state.position_mm);
        k.barrier(local, play.spec.radius_mm, play.state.bottom_mm(&play.spec))
    }

    /// Whether robot `i`'s kicker is charged (false without one).
    pub fn kicker_ready(&self, i: usize) -> bool {
        let r = &self.robots[i];
        r.spec.kicker.is_some() && self.time_s() >= r.kicker_ready_at_s
    }

    /// The ball's description and state, when there is a ball.
    pub fn ball(&self) -> Option<(&BallSpec, BallState)> {
        self.play.as_ref().map(|p| (&p.spec, p.state))
    }

    /// The ball as the renderers see it: a sphere labelled `ball` (none without a ball).
    pub fn spheres(&self) -> Vec<crate::sphere::Sphere> {
        (self.play.iter())
            .map(|p| crate::sphere::Sphere {
                center_mm: [
                    p.state.position_mm.x,
                    p.state.position_mm.y,
                    p.state.height_mm,
                ],
                radius_mm: p.spec.radius_mm,
                rgb: p.spec.rgb,
                object: ObjectId::of(Class::Ball),
            })
            .collect()
    }

    /// The robot whose dribbler holds the ball.
    pub fn ball_holder(&self) -> Option<usize> {
        self.play.as_ref().and_then(play::Play::holder)
    }

    /// Puts the ball at `position_mm` on the floor going at `velocity_mm_s` (an experimenter
    /// placing it; a dribbler holding it lets go). Nothing without a ball.
    pub fn place_ball(&mut self, position_mm: Point2<f64>, velocity_mm_s: Vector2<f64>) {
        if let Some(p) = &mut self.play {
            p.hold = None;
            p.state = BallState::on_floor(&p.spec, position_mm, velocity_mm_s);
        }
    }

    /// The ball rolls from now on at its present speed (no sliding phase first): a ball set
    /// going with the spin of rolling. Nothing without a ball.
    pub fn set_ball_rolling(&mut self) {
        if let Some(p) = &mut self.play {
            p.state.roll_below_mm_s = p.state.velocity_mm_s.norm();
        }
    }

    /// The game's events so far (kicks, touches, goals, ...), in order.
    pub fn ball_events(&self) -> &[BallEvent] {
        self.play.as_ref().map_or(&[], |p| p.referee.events())
    }

    /// The game's figures of the ball so far, when there is a ball.
    pub fn ball_figures(&self) -> Option<&BallFigures> {
        self.play.as_ref().map(|p| p.referee.figures())
    }

    /// Decides which pairs rapier reports truly touch (rapier keeps speculative contacts and
    /// recycles manifolds, so it is decided from their exact distance) and counts each touch
    /// that begins: for the robot, by what it touched, and once for a pair of robots.
    fn confirm_contacts(&mut self) {
        for i in 0..self.robots.len() {
            let pairs = std::mem::take(&mut self.robots[i].pairs);
            let mut checked = Vec::with_capacity(pairs.len());
            for (other, touching) in pairs {
                let now = self.gap_mm(i, other) <= TOUCH_TOLERANCE_MM;
                if now && !touching {
                    let owner = self.owner(other);
                    let class = owner.map(|o| self.object(o).class);
                    let st = &mut self.robots[i].stats;
                    st.contacts += 1;
                    if let Some(class) = class {
                        st.contacts_by_class.add(class);
                    }
                    match owner {
                        Some(Owner::Robot(j)) => {
                            st.robot_contacts += 1;
                            // The other robot sees the same touch; count it from the lower index.
                            if i < j {
                                self.robot_touches.push((i, j));
                            }
                        }
                        _ => st.solid_contacts += 1,
                    }
                }
                checked.push((other, now));
            }
            self.robots[i].pairs = checked;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Wall;

    fn robot_at(x: f64, y: f64) -> RobotBodySpec {
        RobotBodySpec {
            start: Isometry2::new(Vector2::new(x, y), 0.0),
            radius_mm: 90.0,
            height_mm: 140.0,
            accel_limit_mm_s2: 300.0,
            angular_accel_limit_rad_s2: 10.0,
            max_speed_mm_s: 3000.0,
            rgb: Rgb([20, 20, 20]),
            marking_rgb: None,
            differential: None,
            kicker: None,
        }
    }

    fn wall_layout() -> Layout {
        Layout {
            walls: vec![Wall {
                from_mm: [500.0, -1000.0],
                to_mm: [500.0, 1000.0],
                thickness_mm: 100.0,
                height_mm: 150.0,
                rgb: Rgb([235, 235, 235]),
            }],
            ..Layout::default()
        }
    }

    #[test]
    fn free_motion_follows_the_drive_model_exactly() {
        let mut w = World::new(&Layout::default(), &[robot_at(0.0, 0.0)], 0.002).unwrap();
        w.set_command(0, VelocityCommand::translate(Vector2::new(0.0, 400.0)));
        w.advance(1.0);
        let s = w.robot_state(0);
        // 300 mm/s^2 for 1 s from rest: 300 mm/s.
        assert!((s.velocity_mm_s.y - 300.0).abs() < 1e-2, "{s:?}");
        // Displacement alpha t^2 / 2 = 150 mm, up to the step's discretisation.
        assert!((s.pose.translation.y - 150.0).abs() < 0.5, "{s:?}");
        assert!(w.stats(0).peak_accel_mm_s2 <= 300.0 * 1.01);
        assert_eq!(w.stats(0).contacts, 0);
    }

    #[test]
    fn a_robot_driven_into_a_wall_at_2000_mm_s_stays_outside_and_the_contact_is_counted() {
        let mut spec = robot_at(0.0, 0.0);
        spec.accel_limit_mm_s2 = 20_000.0;
        let mut w = World::new(&wall_layout(), &[spec], 0.002).unwrap();
        w.set_command(0, VelocityCommand::translate(Vector2::new(2000.0, 0.0)));
        let mut max_x: f64 = 0.0;
        for _ in 0..100 {
            w.advance(0.02);
            max_x = max_x.max(w.robot_state(0).pose.translation.x);
        }
        // The wall's face is at x = 450; the robot's centre must stay at or before 360.
        assert!(max_x <= 450.0 - 90.0 + 1.0, "max x {max_x}");
        assert!(w.clearance_mm(0) > -1.0);
        assert_eq!(w.stats(0).contacts, 1);
        assert!(w.stats(0).min_clearance_mm > -1.0);
    }

    #[test]
    fn passing_close_to_a_wall_is_not_a_contact() {
        let mut w = World::new(&wall_layout(), &[robot_at(350.0, -800.0)], 0.002).unwrap();
        // Centre at x = 350: the robot's edge passes 10 mm from the wall face.
        w.set_command(0, VelocityCommand::translate(Vector2::new(0.0, 400.0)));
        w.advance(3.0);
        assert_eq!(w.stats(0).contacts, 0);
        assert!((w.stats(0).min_clearance_mm - 10.0).abs() < 0.5);
    }

    #[test]
    fn a_command_over_the_top_speed_is_scaled_down_by_its_norm() {
        let mut spec = robot_at(0.0, 0.0);
        spec.max_speed_mm_s = 400.0;
        let mut w = World::new(&Layout::default(), &[spec], 0.002).unwrap();
        // A diagonal 400 mm/s on each axis: 566 mm/s, taken as 400 along the same direction.
        w.set_command(0, VelocityCommand::translate(Vector2::new(400.0, 400.0)));
        let c = w.command(0).v_mm_s;
        assert!(
            (c.norm() - 400.0).abs() < 1e-9 && (c.x - c.y).abs() < 1e-9,
            "{c}"
        );
        w.advance(3.0);
        let v = w.robot_state(0).velocity_mm_s;
        assert!((v.norm() - 400.0).abs() < 0.5, "{v}");
        // Within the top speed: as given.
        w.set_command(0, VelocityCommand::translate(Vector2::new(100.0, -50.0)));
        assert_eq!(w.command(0).v_mm_s, Vector2::new(100.0, -50.0));
    }

    #[test]
    fn a_placed_robot_is_where_it_was_put_and_at_rest() {
        let mut w = World::new(&Layout::default(), &[robot_at(0.0, 0.0)], 0.002).unwrap();
        w.set_command(0, VelocityCommand::translate(Vector2::new(300.0, 0.0)));
        w.advance(0.5);
        w.place_robot(0, Isometry2::new(Vector2::new(-400.0, 250.0), 1.0));
        let s = w.robot_state(0);
        assert!((s.pose.translation.vector - Vector2::new(-400.0, 250.0)).norm() < 1e-3);
        assert!((s.pose.rotation.angle() - 1.0).abs() < 1e-6);
        assert_eq!(s.velocity_mm_s, Vector2::zeros());
        w.advance(0.1);
        assert!((w.robot_state(0).pose.translation.x + 400.0).abs() < 1e-3);
    }

    #[test]
    fn a_differential_robot_moves_along_its_heading_and_turns_on_the_spot() {
        let mut spec = robot_at(0.0, 0.0);
        spec.start = Isometry2::new(Vector2::zeros(), std::f64::consts::FRAC_PI_2);
        spec.differential =
            Some(DifferentialDrive::new(100.0, 200.0, 90f64.to_radians(), 1000.0, 20.0).unwrap());
        let mut w = World::new(&Layout::default(), &[spec], 0.002).unwrap();
        // Asked to go sideways (world +x while facing +y): it stays where it is.
        w.set_command(0, VelocityCommand::translate(Vector2::new(150.0, 0.0)));
        w.advance(0.5);
        assert!(w.robot_state(0).pose.translation.vector.norm() < 1e-3);
        // Forward at 150 mm/s for 1 s: 0.15 s of acceleration, then steady.
        w.set_command(0, VelocityCommand::translate(Vector2::new(0.0, 150.0)));
        w.advance(1.0);
        let s = w.robot_state(0);
        assert!(
            (s.pose.translation.y - (150.0 - 0.5 * 150.0 * 0.15)).abs() < 1.0,
            "{s:?}"
        );
        assert!(s.pose.translation.x.abs() < 1e-3);
        // Turning on the spot at the 90 deg/s limit while stopping: no drift sideways.
        w.set_command(
            0,
            VelocityCommand {
                v_mm_s: Vector2::zeros(),
                omega_rad_s: 3.0,
            },
        );
        let before = w.robot_state(0);
        w.advance(1.0);
        let after = w.robot_state(0);
        assert!((after.omega_rad_s - 90f64.to_radians()).abs() < 1e-3);
        let moved = after.pose.translation.vector - before.pose.translation.vector;
        // It stops within v^2 / (2 a) = 11.25 mm, along its heading as it turns.
        assert!(moved.norm() < 12.0, "{moved:?}");
    }

    #[test]
    fn a_touch_between_two_robots_is_counted_by_what_was_touched_and_once_for_the_pair() {
        let (mut a, mut b) = (robot_at(-400.0, 0.0), robot_at(0.0, 0.0));
        a.accel_limit_mm_s2 = 2000.0;
        b.accel_limit_mm_s2 = 2000.0;
        let mut w = World::new(&wall_layout(), &[a, b], 0.002).unwrap();
        w.set_command(0, VelocityCommand::translate(Vector2::new(300.0, 0.0)));
        w.set_command(1, VelocityCommand::translate(Vector2::new(-300.0, 0.0)));
        w.advance(1.0);
        for i in 0..2 {
            let st = w.stats(i);
            assert_eq!(
                (st.contacts, st.robot_contacts, st.solid_contacts),
                (1, 1, 0)
            );
            assert!(st.min_robot_clearance_mm <= TOUCH_TOLERANCE_MM);
        }
        assert_eq!(w.robot_touches(), &[(0, 1)]);
        // Robot 1 then drives on into the wall's face at x = 450: a solid's touch, not a pair's.
        w.set_command(0, VelocityCommand::translate(Vector2::new(-300.0, 0.0)));
        w.set_command(1, VelocityCommand::translate(Vector2::new(300.0, 0.0)));
        w.advance(2.5);
        assert_eq!(w.stats(1).solid_contacts, 1);
        assert_eq!(w.robot_touches().len(), 1);
        let by_class: Vec<_> = w.stats(1).contacts_by_class.touched().collect();
        assert_eq!(by_class, [(Class::Wall, 1), (Class::Robot, 1)]);
    }

    #[test]
    fn a_touch_is_classified_by_the_touched_collider_own_object() {
        let layout = Layout {
            cubes: vec![crate::Cube {
                center_mm: [300.0, 0.0],
                size_mm: 130.0,
                angle_deg: 0.0,
                rgb: Rgb([40, 40, 40]),
            }],
            ..Layout::default()
        };
        let mut w = World::new(&layout, &[robot_at(0.0, 0.0)], 0.002).unwrap();
        w.set_command(0, VelocityCommand::translate(Vector2::new(300.0, 0.0)));
        w.advance(2.0);
        let st = w.stats(0);
        assert_eq!((st.contacts, st.solid_contacts), (1, 1));
        assert_eq!(st.contacts_by_class.of(Class::Cube), 1);
        assert_eq!(st.contacts_by_class.of(Class::Wall), 0);
        // The collider names its owner; nothing else does.
        for (h, c) in w.physics.colliders.iter() {
            let owner = Owner::of(c.user_data).unwrap();
            assert_eq!(w.owner(h), Some(owner));
        }
        assert_eq!(Owner::of(0), None);
    }

    #[test]
    fn ray_cast_sees_walls_and_other_robots() {
        let w = World::new(
            &wall_layout(),
            &[robot_at(0.0, 0.0), robot_at(0.0, 300.0)],
            0.002,
        )
        .unwrap();
        let d = w
            .ray_cast_mm(Point2::origin(), Vector2::new(1.0, 0.0), 5000.0, Some(0))
            .unwrap();
        assert!((d - 450.0).abs() < 1e-9);
        let d = w
            .ray_cast_mm(Point2::origin(), Vector2::new(0.0, 1.0), 5000.0, Some(0))
            .unwrap();
        assert!((d - 210.0).abs() < 1e-3);
    }
}
