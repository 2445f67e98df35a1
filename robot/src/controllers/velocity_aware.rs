//! Velocity-aware avoidance (Sect. 3.2 of the corner paper), from the image; with chosen
//! speeds, a near-field memory supplies where obstacles are inside the camera's blind zone;
//! with a planner (`[control.planner]`, on by default), the goal it heads for is a lookahead
//! point on a plan over the map the robot builds, and the controller stays the safety layer.

use super::goal_direction::check_avoidance;
use crate::boundary::BodyCommand;
use crate::controller::{
    ControlTable, Controller, ControllerEntry, Situation, no_problems, settings, with_surroundings,
};
use crate::navigation::{
    self, MapSnapshot, NavigationReport, Navigator, PlannerConfig, PlannerKind,
};
use crate::near_field::{NearField, NearSpace};
use crate::traffic::TrafficSense;
use nalgebra::Isometry2;
use omniloop_control::{
    AccelLimitedDrive, AvoidanceConfig, GoalKind, SpeedChoice, TrafficConfig, VelocityAware,
};
use omniloop_vision::FreeSpace;

/// The registry's entry.
pub const ENTRY: ControllerEntry = ControllerEntry {
    name: "velocity_aware",
    summary: "velocity-aware avoidance, eq. (8) predicted paths (Sect. 3.2 of the corner paper), \
              under a planner on the map the robot builds",
    tables: &[
        ControlTable {
            name: "avoidance",
            check: check_avoidance,
        },
        ControlTable {
            name: navigation::TABLE,
            check: navigation::check_planner,
        },
    ],
    needs_goal: true,
    stages: &[crate::perception::freespace::NAME],
    check_use: no_problems,
    build: |c| {
        let b = &c.body;
        let drive = AccelLimitedDrive::new(b.accel_limit_mm_s2, b.angular_accel_limit_rad_s2)?;
        let avoid: AvoidanceConfig = settings(c, "avoidance")?;
        let planner: PlannerConfig = settings(c, navigation::TABLE)?;
        let navigator = match planner.kind {
            PlannerKind::Grid => Some(Navigator::new(c, planner)?),
            PlannerKind::None => None,
        };
        Ok(Box::new(VelocityAwareStack {
            near: (avoid.speed == SpeedChoice::Chosen).then(|| NearField::new(b.radius_mm)),
            traffic: avoid
                .traffic
                .reciprocal()
                .then(|| TrafficSense::new(&c.map, &avoid.traffic)),
            rule: avoid.traffic.clone(),
            radius_mm: b.radius_mm,
            controller: VelocityAware::new(
                avoid,
                drive,
                b.max_speed_mm_s,
                b.radius_mm,
                c.control_period_s,
            )?,
            navigator,
        }))
    },
};

/// The velocity-aware controller with its near-field memory (chosen speeds only) and its
/// navigator (with a planner).
pub struct VelocityAwareStack {
    controller: VelocityAware,
    near: Option<NearField>,
    navigator: Option<Navigator>,
    /// With the traffic rule: the map and the floor seen free, which tell walls and standing
    /// obstacles from what may move.
    traffic: Option<TrafficSense>,
    /// The traffic rule's settings.
    rule: TrafficConfig,
    /// The robot's radius, mm.
    radius_mm: f64,
}

/// Moves each blind point out along its ray to where the map's floor seen free ends
/// ([`Navigator::free_along`]): the memory by the body forgets in 2 s and 250 mm of travel, the
/// map keeps what it saw for `forget_s`, in the localized frame. A blind point stays a blind
/// point (passed at a slant, never headed into), only no nearer than the map allows: a robot
/// that stood in a 305 mm gap's mouth until its memory of the floor there lapsed no longer
/// finds phantoms at its body's edge on both sides (the planner's clearance and the
/// controller's are then the same: see docs/navigation.md).
fn push_blind_out(space: &mut NearSpace, nav: &Navigator, pose: &Isometry2<f64>, inner_mm: f64) {
    for b in &mut space.blind {
        let r = b.norm();
        if r < 1e-6 || r >= inner_mm {
            continue;
        }
        let d = nav.free_along(pose, *b / r, r, inner_mm);
        if d > r {
            *b *= d / r;
        }
    }
}

impl Controller for VelocityAwareStack {
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand {
        let mut clear = match (&mut self.near, s.percept::<FreeSpace>()) {
            (Some(near), Some(fs)) => Some(near.update(fs, &s.odometry_pose, s.t_s)),
            _ => None,
        };
        if let (Some(space), Some(nav), Some(pose), Some(fs)) = (
            &mut clear,
            &self.navigator,
            &s.pose,
            s.percept::<FreeSpace>(),
        ) {
            push_blind_out(space, nav, pose, fs.inner_mm);
        }
        let traffic = match (&mut self.traffic, s.percept::<FreeSpace>()) {
            (Some(sense), Some(fs)) => {
                Some(sense.update(fs, s.pose.as_ref(), &s.odometry_pose, s.t_s))
            }
            _ => None,
        };
        let (target_body_mm, kind) = match (&mut self.navigator, &s.pose, s.target_mm) {
            (Some(nav), Some(pose), Some(target)) => {
                let to = nav.steer(
                    s.percept::<FreeSpace>(),
                    pose,
                    s.velocity_body_mm_s,
                    target,
                    s.t_s,
                );
                let kind = if nav.on_final_leg() {
                    GoalKind::InSight
                } else {
                    GoalKind::Ahead
                };
                (to, kind)
            }
            _ => (s.target_body_mm, GoalKind::Ahead),
        };
        // With the traffic rule's yield_mm, a robot at its target makes way for what moves.
        let rule = &self.rule;
        let (target_body_mm, kind) = match (&traffic, s.target_body_mm) {
            (Some(tp), Some(t)) if rule.yield_mm > 0.0 && t.norm() <= rule.yield_mm => {
                let to = rule.make_way(t, &tp.moving, self.radius_mm);
                match to == t {
                    true => (target_body_mm, kind),
                    false => (Some(to), GoalKind::Ahead),
                }
            }
            _ => (target_body_mm, kind),
        };
        let s = Situation {
            target_body_mm,
            ..*s
        };
        let v = s.velocity_body_mm_s;
        let c = &self.controller;
        let command = with_surroundings(&s, clear, traffic.as_ref(), |sur, target| {
            c.decide_toward(sur, target, kind, v).v_mm_s
        });
        // The navigator hears what the controller made of its step.
        if let (Some(nav), Some(pose)) = (&mut self.navigator, &s.pose) {
            nav.heard(command.v_mm_s, v, pose, s.t_s);
        }
        command
    }

    fn navigation(&self) -> Option<&NavigationReport> {
        self.navigator.as_ref().map(Navigator::report)
    }

    fn map(&self) -> Option<MapSnapshot> {
        self.navigator.as_ref().map(Navigator::map)
    }
}
