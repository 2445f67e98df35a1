//! The ball in the world, every physics step: held on a dribbler or moving freely, bouncing
//! off solids and robots, caught by a dribbler, kicked; the referee watching
//! ([`crate::ball`], [`crate::kicker`] and [`crate::game`] state the models).

use super::World;
use crate::ball::{BallSpec, BallState};
use crate::game::{BallEvent, MAX_DRIBBLE_MM, Referee, Release};
use crate::kicker::{BallCommand, KickerSpec, body_distance};
use crate::shapes::Solid;
use nalgebra::{Isometry2, Point2, Vector2};

/// A ball this close (mm) to a robot's body still touches it.
const TOUCH_MM: f64 = 0.5;

/// The ball and what the world knows of its play.
pub(super) struct Play {
    pub(super) spec: BallSpec,
    pub(super) state: BallState,
    pub(super) hold: Option<Hold>,
    /// Per robot: until when its dribbler cannot catch the ball (after losing or kicking it).
    pub(super) no_catch_until_s: Vec<f64>,
    /// Per robot: whether the ball touched its body at the last step (a touch is counted
    /// when one begins).
    touching: Vec<bool>,
    pub(super) referee: Referee,
}

/// A ball held on a dribbler.
#[derive(Debug, Clone, Copy)]
pub(super) struct Hold {
    robot: usize,
    /// Where across the front the ball sits (robot frame y).
    offset_mm: f64,
    /// The front point's velocity at the last step (world frame).
    front_velocity_mm_s: Vector2<f64>,
    /// Where the robot was when it caught the ball.
    caught_at: Point2<f64>,
    /// Whether the dribble was already reported as too long.
    too_far: bool,
}

/// A robot as the ball meets it: its pose, velocity, size and kicker.
#[derive(Debug, Clone, Copy)]
pub(super) struct Body {
    pose: Isometry2<f64>,
    velocity_mm_s: Vector2<f64>,
    omega_rad_s: f64,
    radius_mm: f64,
    height_mm: f64,
    kicker: Option<KickerSpec>,
    command: BallCommand,
}

impl Body {
    /// The velocity of the body's point `p` (world frame).
    fn velocity_at(&self, p: Point2<f64>) -> Vector2<f64> {
        let r = p - Point2::from(self.pose.translation.vector);
        self.velocity_mm_s + Vector2::new(-r.y, r.x) * self.omega_rad_s
    }

    /// `p` in the body's frame.
    fn local(&self, p: Point2<f64>) -> Point2<f64> {
        self.pose.inverse_transform_point(&p)
    }

    /// Whether its light barrier sees the ball.
    fn barrier(&self, spec: &BallSpec, ball: &BallState) -> bool {
        self.kicker.is_some_and(|k| {
            k.barrier(
                self.local(ball.position_mm),
                spec.radius_mm,
                ball.bottom_mm(spec),
            )
        })
    }
}

/// Unit normal of a solid's footprint at `p`: the gradient of its signed distance.
fn solid_normal(s: &Solid, p: Point2<f64>) -> Vector2<f64> {
    const H: f64 = 1e-3;
    let d = |q: Point2<f64>| s.shape.distance_mm(q);
    let g = Vector2::new(
        d(p + Vector2::new(H, 0.0)) - d(p - Vector2::new(H, 0.0)),
        d(p + Vector2::new(0.0, H)) - d(p - Vector2::new(0.0, H)),
    );
    let n = g.norm();
    if n > 1e-12 {
        g / n
    } else {
        Vector2::new(1.0, 0.0)
    }
}

impl Play {
    pub(super) fn new(spec: &BallSpec, robots: usize, referee: Referee) -> Self {
        Self {
            state: BallState::on_floor(
                spec,
                Point2::from(spec.center_mm),
                Vector2::from(spec.velocity_mm_s),
            ),
            spec: spec.clone(),
            hold: None,
            no_catch_until_s: vec![f64::NEG_INFINITY; robots],
            touching: vec![false; robots],
            referee,
        }
    }

    /// Who holds the ball on a dribbler.
    pub(super) fn holder(&self) -> Option<usize> {
        self.hold.map(|h| h.robot)
    }

    /// One physics step of `dt_s` ending at `t_s`, the robots already moved.
    pub(super) fn step(
        &mut self,
        t_s: f64,
        dt_s: f64,
        solids: &[Solid],
        bodies: &[Body],
    ) -> Vec<usize> {
        let held = self.hold.is_some() && self.keep_hold(t_s, dt_s, bodies);
        // A ball lost this step moves on freely from where it was.
        if !held {
            self.state.advance(&self.spec, dt_s);
            self.bounce_off_solids(solids);
            self.bounce_off_robots(t_s, bodies);
            self.catch(t_s, bodies);
        }
        let kicked = self.kicks(t_s, bodies);
        let holder = self.holder();
        (self.referee).observe(t_s, dt_s, &self.spec, &self.state, holder);
        kicked
    }

    /// Keeps the ball on its holder's dribbler if the dribbler can pull what the front's motion
    /// asks; else lets it go as it was going. Whether it is still held.
    fn keep_hold(&mut self, t_s: f64, dt_s: f64, bodies: &[Body]) -> bool {
        let Some(mut h) = self.hold else {
            return false;
        };
        let b = &bodies[h.robot];
        let Some(k) = b.kicker else {
            return false;
        };
        let front = k.front_mm + self.spec.radius_mm;
        let p = b.pose * Point2::new(front, h.offset_mm);
        let v = b.velocity_at(p);
        let accel = b.pose.rotation.inverse() * ((v - h.front_velocity_mm_s) / dt_s);
        let robot = Point2::from(b.pose.translation.vector);
        let dribbled = (robot - h.caught_at).norm();
        let rpm = b.command.dribbler_rpm;
        if !(rpm > 0.0 && k.can_hold(rpm, accel)) {
            self.state.velocity_mm_s = h.front_velocity_mm_s;
            self.state.roll_below_mm_s = self.spec.roll_fraction * v.norm();
            let cause = match rpm > 0.0 {
                true => Release::Pull,
                false => Release::DribblerOff,
            };
            self.release(t_s, &k, dribbled, cause);
            return false;
        }
        self.state.position_mm = p;
        self.state.height_mm = self.spec.radius_mm;
        self.state.vz_mm_s = 0.0;
        self.state.velocity_mm_s = v;
        self.state.roll_below_mm_s = self.spec.roll_fraction * v.norm();
        h.front_velocity_mm_s = v;
        if dribbled > MAX_DRIBBLE_MM && !h.too_far {
            h.too_far = true;
            let robot = h.robot;
            self.referee.event(BallEvent::DribbledTooFar { t_s, robot });
        }
        self.hold = Some(h);
        true
    }

    /// The holder lets the ball go: it cannot catch it again for a while.
    fn release(&mut self, t_s: f64, k: &KickerSpec, dribbled_mm: f64, cause: Release) {
        if let Some(h) = self.hold.take() {
            self.no_catch_until_s[h.robot] = t_s + k.regrab_s;
            (self.referee).event(BallEvent::Released {
                t_s,
                robot: h.robot,
                dribbled_mm,
                cause,
            });
        }
    }

    fn bounce_off_solids(&mut self, solids: &[Solid]) {
        let r = self.spec.radius_mm;
        let (bottom, top) = (self.state.bottom_mm(&self.spec), self.state.height_mm + r);
        for s in solids {
            // A solid lower than the ball's bottom, or raised above its top, is passed.
            if s.height_mm <= bottom || s.base_mm >= top {
                continue;
            }
            let p = self.state.position_mm;
            let d = s.shape.distance_mm(p);
            if d < r {
                let n = solid_normal(s, p);
                self.state.bounce(&self.spec, n, r - d, Vector2::zeros());
            }
        }
    }

    fn bounce_off_robots(&mut self, t_s: f64, bodies: &[Body]) {
        let r = self.spec.radius_mm;
        let bottom = self.state.bottom_mm(&self.spec);
        for (j, b) in bodies.iter().enumerate() {
            if b.height_mm <= bottom {
                continue;
            }
            let p = self.state.position_mm;
            let front = b.kicker.map(|k| k.front_mm);
            let (d, n_local) = body_distance(b.local(p), b.radius_mm, front);
            let was = std::mem::replace(&mut self.touching[j], d < r + TOUCH_MM);
            if d >= r {
                continue;
            }
            let n = b.pose.rotation * n_local;
            if self.state.bounce(&self.spec, n, r - d, b.velocity_at(p)) && !was {
                self.referee.event(BallEvent::Touch { t_s, robot: j });
            }
        }
    }

    /// A spinning dribbler whose barrier sees the ball catches it.
    fn catch(&mut self, t_s: f64, bodies: &[Body]) {
        for (j, b) in bodies.iter().enumerate() {
            let ready = t_s >= self.no_catch_until_s[j];
            if !(ready && b.command.dribbler_rpm > 0.0 && b.barrier(&self.spec, &self.state)) {
                continue;
            }
            let local = b.local(self.state.position_mm);
            let p = self.state.position_mm;
            self.hold = Some(Hold {
                robot: j,
                offset_mm: local.y,
                front_velocity_mm_s: b.velocity_at(p),
                caught_at: Point2::from(b.pose.translation.vector),
                too_far: false,
            });
            self.referee.event(BallEvent::Captured { t_s, robot: j });
            return;
        }
    }

    /// Fires every armed, charged kicker whose barrier sees the ball; the robots that kicked.
    fn kicks(&mut self, t_s: f64, bodies: &[Body]) -> Vec<usize> {
        let mut kicked = Vec::new();
        for (j, b) in bodies.iter().enumerate() {
            let (Some(k), Some(kick)) = (b.kicker, b.command.kick) else {
                continue;
            };
            if !(self.holder() == Some(j) || b.barrier(&self.spec, &self.state)) {
                continue;
            }
            let p = self.state.position_mm;
            let speed = kick.speed_mm_s.clamp(0.0, k.max_kick_mm_s);
            let heading = b.pose.rotation * Vector2::new(1.0, 0.0);
            let (s, c) = kick.angle_rad.sin_cos();
            let v = b.velocity_at(p) + heading * (speed * c);
            let robot = Point2::from(b.pose.translation.vector);
            let dribbled = self.hold.map_or(0.0, |h| (robot - h.caught_at).norm());
            self.release(t_s, &k, dribbled, Release::Kick);
            self.no_catch_until_s[j] = t_s + k.regrab_s;
            self.state.launch(&self.spec, v, speed * s);
            self.referee.event(BallEvent::Kick {
                t_s,
                robot: j,
                speed_mm_s: speed,
                angle_rad: kick.angle_rad,
            });
            kicked.push(j);
            break;
        }
        kicked
    }
}

impl World {
    /// The robots as the ball meets them.
    pub(super) fn ball_bodies(&self) -> Vec<Body> {
        (0..self.robots.len())
            .map(|i| {
                let s = self.robot_state(i);
                let r = &self.robots[i];
                Body {
                    pose: s.pose,
                    velocity_mm_s: s.velocity_mm_s,
                    omega_rad_s: s.omega_rad_s,
                    radius_mm: r.spec.radius_mm,
                    height_mm: r.spec.height_mm,
                    kicker: r.spec.kicker,
                    command: if self.time_s() >= r.kicker_ready_at_s {
                        r.ball_command
                    } else {
                        BallCommand {
                            kick: None,
                            ..r.ball_command
                        }
                    },
                }
            })
            .collect()
    }
}
