//! The simulation-control port's commands on [`SslSimulator`]: the ball and robots teleported
//! (robots added and removed with `present`), the simulation's speed, the vision port and the
//! robots' wheel angles. Every other field a client sets is answered with a `SimulatorError`
//! naming it, as the protocol asks: the field, the robots' bodies and the realism are the
//! scenario's.

use super::commands::error;
use super::engine::SslLink;
use super::wire::sim::{
    RobotSpecs, SimulatorCommand, SimulatorConfig, SimulatorError, Team, TeleportBall,
    TeleportRobot,
};
use crate::run::Simulation;
use crate::scenario::ssl::TeamColor;
use nalgebra::{Isometry2, Point2, Vector2};

/// The fastest speed a client may set, simulated time over wall time.
const MAX_SPEED: f64 = 100.0;

fn unsupported(field: &str, why: &str) -> SimulatorError {
    error("UNSUPPORTED_FIELD", format!("{field}: {why}"))
}

impl SslLink {
    /// Applies a `SimulatorCommand`: the errors, one for each field not taken.
    pub(crate) fn apply_simulator_command(
        &mut self,
        sim: &mut Simulation,
        c: &SimulatorCommand,
    ) -> Vec<SimulatorError> {
        let mut errors = Vec::new();
        if let Some(control) = &c.control {
            if let Some(b) = &control.teleport_ball {
                errors.extend(self.teleport_ball(sim, b));
            }
            for (k, r) in control.teleport_robot.iter().enumerate() {
                errors.extend(self.teleport_robot(sim, k, r));
            }
            if let Some(s) = control.simulation_speed.map(f64::from) {
                if s.is_finite() && s > 0.0 && s <= MAX_SPEED {
                    self.speed = s;
                } else {
                    errors.push(error(
                        "INVALID_SPEED",
                        format!("simulation_speed {s}: it must be above 0 and at most {MAX_SPEED}"),
                    ));
                }
            }
        }
        if let Some(config) = &c.config {
            errors.extend(self.configure(config));
        }
        errors
    }

    fn teleport_ball(&mut self, sim: &mut Simulation, b: &TeleportBall) -> Vec<SimulatorError> {
        let mut errors = Vec::new();
        let Some((_, now)) = sim.world().ball() else {
            return vec![error(
                "NO_BALL",
                "the scenario has no ball ([world.ball])".into(),
            )];
        };
        let metres = |v: Option<f32>, old: f64| v.map_or(old, |v| f64::from(v) * 1000.0);
        let at = Point2::new(
            metres(b.x, now.position_mm.x),
            metres(b.y, now.position_mm.y),
        );
        let v = Vector2::new(metres(b.vx, 0.0), metres(b.vy, 0.0));
        for (field, set) in [
            ("teleport_ball.z", b.z.is_some_and(|z| z != 0.0)),
            ("teleport_ball.vz", b.vz.is_some_and(|z| z != 0.0)),
            ("teleport_ball.by_force", b.by_force == Some(true)),
        ] {
            if set {
                errors.push(unsupported(
                    field,
                    "the ball is placed on the floor, at once",
                ));
            }
        }
        if b.teleport_safely == Some(true) {
            self.clear_robots_from(sim, at);
        }
        match sim.place_ball(at, v) {
            Ok(()) if b.roll == Some(true) => sim.set_ball_rolling(),
            Ok(()) => {}
            Err(e) => errors.push(error("INVALID_TELEPORT", e.to_string())),
        }
        errors
    }

    /// Moves every robot on the field that would touch a ball at `at` out of its way.
    fn clear_robots_from(&mut self, sim: &mut Simulation, at: Point2<f64>) {
        let ball_r = sim.world().ball().map_or(21.5, |(s, _)| s.radius_mm);
        for k in 0..self.robots.len() {
            let r = &self.robots[k];
            if !r.present {
                continue;
            }
            let pose = sim.world().robot_state(r.body).pose;
            let off = pose.translation.vector - at.coords;
            let clear = r.radius_mm + ball_r + 20.0;
            if off.norm() < clear {
                let dir = if off.norm() > 1e-6 {
                    off.normalize()
                } else {
                    Vector2::x()
                };
                let to = at.coords + dir * clear;
                let agent = r.agent;
                sim.carry_robot(agent, Isometry2::new(to, pose.rotation.angle()));
            }
        }
    }

    fn teleport_robot(
        &mut self,
        sim: &mut Simulation,
        k: usize,
        t: &TeleportRobot,
    ) -> Vec<SimulatorError> {
        let field = |f: &str| format!("teleport_robot[{k}].{f}");
        let team = match t.id.team.and_then(|v| Team::try_from(v).ok()) {
            Some(Team::Blue) => TeamColor::Blue,
            Some(Team::Yellow) => TeamColor::Yellow,
            _ => {
                return vec![error(
                    "INVALID_TEAM",
                    format!("{}: blue or yellow", field("id.team")),
                )];
            }
        };
        let id = t.id.id.unwrap_or(u32::MAX);
        let Some(&r) = self.by_id.get(&(team, id)) else {
            return vec![error(
                "UNKNOWN_ROBOT",
                format!(
                    "{}: no {} robot {id} in the scenario; add it to [[robots]] and [ssl]",
                    field("id"),
                    team.name()
                ),
            )];
        };
        let mut errors = Vec::new();
        for (f, set) in [
            ("v_x", t.v_x.is_some_and(|v| v != 0.0)),
            ("v_y", t.v_y.is_some_and(|v| v != 0.0)),
            ("v_angular", t.v_angular.is_some_and(|v| v != 0.0)),
            ("by_force", t.by_force == Some(true)),
        ] {
            if set {
                errors.push(unsupported(&field(f), "robots are placed at rest, at once"));
            }
        }
        let present = t.present.unwrap_or(self.robots[r].present);
        let body = self.robots[r].body;
        let pose = if present {
            let now = sim.world().robot_state(body).pose;
            let parked = !self.robots[r].present;
            let metres = |v: Option<f32>, old: f64| v.map_or(old, |v| f64::from(v) * 1000.0);
            let (x, y) = (now.translation.x, now.translation.y);
            if parked && (t.x.is_none() || t.y.is_none()) {
                errors.push(error(
                    "INVALID_TELEPORT",
                    format!(
                        "{}: a robot put back on the field needs x and y",
                        field("present")
                    ),
                ));
                return errors;
            }
            let at = Vector2::new(metres(t.x, x), metres(t.y, y));
            let heading = t.orientation.map_or(now.rotation.angle(), f64::from);
            let finite = at.iter().all(|v| v.is_finite()) && heading.is_finite();
            if !(finite && sim.world().layout().is_floor(Point2::from(at))) {
                errors.push(error(
                    "INVALID_TELEPORT",
                    format!(
                        "{}: ({}, {}) mm is not on the floor",
                        field("x"),
                        at.x,
                        at.y
                    ),
                ));
                return errors;
            }
            Isometry2::new(at, heading)
        } else {
            self.parking(sim, r)
        };
        self.robots[r].present = present;
        let agent = self.robots[r].agent;
        sim.carry_robot(agent, pose);
        errors
    }

    fn configure(&mut self, c: &SimulatorConfig) -> Vec<SimulatorError> {
        let mut errors = Vec::new();
        if c.geometry.is_some() {
            errors.push(unsupported(
                "config.geometry",
                "the field is the scenario's ([world.field])",
            ));
        }
        if c.realism_config
            .as_ref()
            .is_some_and(|r| !r.custom.is_empty())
        {
            errors.push(unsupported(
                "config.realism_config",
                "omniloop's realism is the scenario's [ssl.vision.realism]",
            ));
        }
        if let Some(port) = c.vision_port {
            match u16::try_from(port) {
                Ok(p) if p > 0 => self.vision_port = Some(p),
                _ => errors.push(error(
                    "INVALID_PORT",
                    format!("config.vision_port {port} is not a port"),
                )),
            }
        }
        for (k, s) in c.robot_specs.iter().enumerate() {
            errors.extend(self.robot_spec(k, s));
        }
        errors
    }

    /// A robot's specification: its wheel angles taken; any other figure answered unless it
    /// is the scenario's own.
    fn robot_spec(&mut self, k: usize, s: &RobotSpecs) -> Vec<SimulatorError> {
        let field = |f: &str| format!("config.robot_specs[{k}].{f}");
        let team = match s.id.team.and_then(|v| Team::try_from(v).ok()) {
            Some(Team::Yellow) => TeamColor::Yellow,
            _ => TeamColor::Blue,
        };
        let id = s.id.id.unwrap_or(u32::MAX);
        let Some(&r) = self.by_id.get(&(team, id)) else {
            return vec![error(
                "UNKNOWN_ROBOT",
                format!(
                    "{}: no {} robot {id} in the scenario",
                    field("id"),
                    team.name()
                ),
            )];
        };
        let robot = &mut self.robots[r];
        let mut errors = Vec::new();
        let same =
            |v: Option<f32>, mm: f64| v.is_none_or(|m| (f64::from(m) * 1000.0 - mm).abs() < 1.0);
        let kick = robot.abilities.max_kick_mm_s.unwrap_or(0.0);
        for (f, ok) in [
            ("radius", same(s.radius, robot.radius_mm)),
            ("height", same(s.height, robot.height_mm)),
            ("max_linear_kick_speed", same(s.max_linear_kick_speed, kick)),
            ("max_chip_kick_speed", same(s.max_chip_kick_speed, kick)),
            ("mass", s.mass.is_none()),
            ("center_to_dribbler", s.center_to_dribbler.is_none()),
            ("limits", s.limits.is_none()),
            ("custom", s.custom.is_empty()),
        ] {
            if !ok {
                errors.push(unsupported(
                    &field(f),
                    "the robot's body is the scenario's ([robot], [robot.kicker])",
                ));
            }
        }
        if let Some(w) = &s.wheel_angles {
            let a = [w.front_right, w.back_right, w.back_left, w.front_left].map(f64::from);
            if a.iter().all(|v| v.is_finite()) {
                robot.abilities.wheel_angles_rad = a;
            } else {
                errors.push(error(
                    "INVALID_SPEC",
                    format!("{}: not numbers", field("wheel_angles")),
                ));
            }
        }
        errors
    }
}
