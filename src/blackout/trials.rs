//! The vision-blackout challenge's trials: what each stage asks, where the seed places the robot
//! and the ball (as the rules allow), and the scenario of one trial.
//!
//! Facts from the league's technical-challenge rules (2021, and 2019 for the moving ball):
//! every trial starts in HALT, then STOP (the robot must not move), and the timer starts at
//! FORCE_START; a trial lasts at most one minute; stage 1 and 2 place robot and ball anywhere on
//! the field, stage 3 adds a static defender robot inside the defense area and the robot starts
//! in the half of the goal it attacks; the 2019 moving ball is kicked below 6.5 m/s from 3 to
//! 5 m away on a path passing within 0.5 m of the robot, which faces where the ball starts.
//! Our choices where they are silent: the robot's software starts at FORCE_START (in HALT and
//! STOP it does not run, so it cannot move), the robot is told its start pose (the rules show
//! the team the starting diagram) but never the ball's; placements keep 300 mm from the lines
//! and out of the defense areas, the ball at least 400 mm from the robot; the attacked goal
//! is the one at +x; the moving ball rolls at 2 to 6.5 m/s, from a robot kept 2 m from every
//! line where the field allows it (Division B) and 0.5 m on the 4 m x 3 m field; a stage-1
//! trial ends once the robot has stood 0.5 s with the ball on its dribbler, a moving-ball trial
//! at the dribbler's touch or after 10 s (the 2019 rules' time).

use nalgebra::{Point2, Vector2};
use omniloop_sim::{FieldPreset, FieldSpec};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use std::f64::consts::PI;

/// A stage of the challenge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// 2021 stage 1: grab a stationary ball.
    Grab,
    /// 2021 stage 2: score on an empty goal without entering the defense area.
    EmptyGoal,
    /// 2021 stage 3: score past a static defender robot standing in the goal.
    Defended,
    /// 2019: receive a ball kicked toward the robot.
    MovingBall,
}

impl Stage {
    /// Every stage, in the order of the score sheet.
    pub const ALL: [Stage; 4] = [
        Stage::Grab,
        Stage::EmptyGoal,
        Stage::Defended,
        Stage::MovingBall,
    ];

    /// Its name in the score sheet and `summary.json`.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Grab => "stage 1: grab",
            Stage::EmptyGoal => "stage 2: empty goal",
            Stage::Defended => "stage 3: defended goal",
            Stage::MovingBall => "2019: moving ball",
        }
    }

    /// Its key in `summary.json`.
    pub fn key(self) -> &'static str {
        match self {
            Stage::Grab => "stage1",
            Stage::EmptyGoal => "stage2",
            Stage::Defended => "stage3",
            Stage::MovingBall => "moving_ball",
        }
    }

    /// The most points a trial can earn.
    pub fn full_points(self) -> i32 {
        match self {
            Stage::Grab => 3,
            Stage::EmptyGoal | Stage::Defended => 4,
            Stage::MovingBall => 2,
        }
    }

    /// Longest trial, s.
    pub fn duration_s(self) -> f64 {
        match self {
            Stage::MovingBall => 10.0,
            _ => 60.0,
        }
    }
}

/// A field of the challenge, by its scenario preset.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Field {
    /// The preset's name (`[world.field] preset`).
    pub preset: &'static str,
    /// The preset.
    pub kind: FieldPreset,
    /// Half length to the goal lines, mm.
    pub half_length_mm: f64,
    /// Half width, mm.
    pub half_width_mm: f64,
    /// Goal mouth, mm.
    pub goal_width_mm: f64,
    /// Defense area depth and width, mm.
    pub defense_mm: [f64; 2],
}

/// The challenge's remote field: 4 m x 3 m, a 0.7 m goal, a 0.8 m x 2 m defense area.
pub const HARDWARE_CHALLENGE: Field = Field {
    preset: "hardware_challenge",
    kind: FieldPreset::HardwareChallenge,
    half_length_mm: 2000.0,
    half_width_mm: 1500.0,
    goal_width_mm: 700.0,
    defense_mm: [800.0, 2000.0],
};

/// Division B's field: 9 m x 6 m, 1 m goals, 1 m x 2 m defense areas.
pub const DIVISION_B: Field = Field {
    preset: "division_b",
    kind: FieldPreset::DivisionB,
    half_length_mm: 4500.0,
    half_width_mm: 3000.0,
    goal_width_mm: 1000.0,
    defense_mm: [1000.0, 2000.0],
};

impl Field {
    /// Whether `p` lies in a defense area (between its front line and the goal line) grown by
    /// `margin_mm`.
    pub fn in_defense_area(&self, p: Point2<f64>, margin_mm: f64) -> bool {
        p.x.abs() >= self.half_length_mm - self.defense_mm[0] - margin_mm
            && p.x.abs() <= self.half_length_mm + margin_mm
            && p.y.abs() <= 0.5 * self.defense_mm[1] + margin_mm
    }

    /// Whether a body of radius `radius_mm` centred at `p` touches a defense area (its lines
    /// included): the distance from `p` to the area below the radius, round the corners.
    pub fn body_touches_defense_area(&self, p: Point2<f64>, radius_mm: f64) -> bool {
        let [depth, width] = self.defense_mm;
        let x =
            p.x.abs()
                .clamp(self.half_length_mm - depth, self.half_length_mm);
        let y = p.y.clamp(-0.5 * width, 0.5 * width);
        (p - Point2::new(p.x.signum() * x, y)).norm() < radius_mm
    }

    /// Whether `p` lies on the field `margin_mm` in from its lines.
    pub fn inside(&self, p: Point2<f64>, margin_mm: f64) -> bool {
        p.x.abs() <= self.half_length_mm - margin_mm && p.y.abs() <= self.half_width_mm - margin_mm
    }
}

/// Where one trial starts.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement {
    /// The robot's start: position, mm, and heading, rad.
    pub robot: (Point2<f64>, f64),
    /// The ball's start.
    pub ball: Point2<f64>,
    /// The ball's velocity at FORCE_START, mm/s (the moving ball only).
    pub ball_velocity_mm_s: Vector2<f64>,
    /// The static defender's centre (stage 3 only).
    pub defender: Option<Point2<f64>>,
}

/// The robot's radius, mm (E1's body).
pub const ROBOT_RADIUS_MM: f64 = 90.0;

/// A point drawn uniformly on the field `margin_mm` in from its lines, out of the defense
/// areas (grown by `keep_mm`), `x` within `xs`.
fn on_field(
    rng: &mut StdRng,
    f: &Field,
    margin_mm: f64,
    keep_mm: f64,
    xs: [f64; 2],
) -> Point2<f64> {
    loop {
        let p = Point2::new(
            rng.random_range(xs[0]..xs[1]),
            rng.random_range(-f.half_width_mm + margin_mm..f.half_width_mm - margin_mm),
        );
        if f.inside(p, margin_mm) && !f.in_defense_area(p, keep_mm) {
            return p;
        }
    }
}

/// The placement of trial `seed` of `stage` on `field`.
pub fn place(stage: Stage, field: &Field, seed: u64) -> Placement {
    let mut rng = StdRng::seed_from_u64(seed ^ 0xB1AC_0017 ^ (stage as u64) << 40);
    let l = field.half_length_mm;
    let keep = ROBOT_RADIUS_MM + 150.0;
    if stage == Stage::MovingBall {
        return moving_ball(&mut rng, field);
    }
    let xs = match stage {
        Stage::Defended => [0.0, l],
        _ => [-l, l],
    };
    let robot = on_field(&mut rng, field, 300.0, keep, xs);
    let heading = rng.random_range(-PI..PI);
    let ball = loop {
        let b = on_field(&mut rng, field, 300.0, 100.0, [-l, l]);
        if (b - robot).norm() >= 400.0 {
            break b;
        }
    };
    let defender = (stage == Stage::Defended).then(|| {
        let [depth, _] = field.defense_mm;
        Point2::new(
            rng.random_range(l - depth + 2.0 * ROBOT_RADIUS_MM..l - ROBOT_RADIUS_MM - 20.0),
            rng.random_range(-0.5 * field.goal_width_mm..0.5 * field.goal_width_mm),
        )
    });
    Placement {
        robot: (robot, heading),
        ball,
        ball_velocity_mm_s: Vector2::zeros(),
        defender,
    }
}

/// The 2019 moving ball: the robot away from the lines, the ball 3 to 5 m away on the field,
/// rolling at 2 to 6.5 m/s toward a point within 0.5 m of the robot, the robot facing the
/// ball's start.
fn moving_ball(rng: &mut StdRng, field: &Field) -> Placement {
    let edge = if field.half_width_mm >= 2500.0 {
        2000.0
    } else {
        500.0
    };
    let l = field.half_length_mm;
    loop {
        let robot = on_field(
            rng,
            field,
            edge,
            ROBOT_RADIUS_MM + 150.0,
            [-l + edge, l - edge],
        );
        let angle = rng.random_range(-PI..PI);
        let d = rng.random_range(3000.0..5000.0);
        let ball = robot + Vector2::new(angle.cos(), angle.sin()) * d;
        if !field.inside(ball, 200.0) || field.in_defense_area(ball, 100.0) {
            continue;
        }
        let miss = rng.random_range(-500.0..500.0);
        let aim = robot + Vector2::new(-angle.sin(), angle.cos()) * miss;
        let speed = rng.random_range(2000.0..6500.0);
        let to = ball - robot;
        return Placement {
            robot: (robot, to.y.atan2(to.x)),
            ball,
            ball_velocity_mm_s: (aim - ball).normalize() * speed,
            defender: None,
        };
    }
}

/// The scenario of one trial: the field, the ball, the defender, and E1's robot (its
/// 256 x 220 hyperbolic camera with E1's noise, wheel odometry with the noise of
/// `ssl_teams.toml`, the league's kicker) playing the striker, its pose from odometry
/// corrected by floor-region self-localization (E2) on the field's floor outline; `realism`
/// adds rows to `[robot]` (E1's latency and blur tables).
pub fn scenario_text(
    stage: Stage,
    field: &Field,
    p: &Placement,
    seed: u64,
    realism: bool,
) -> String {
    let (r, heading) = p.robot;
    let task = if matches!(stage, Stage::Grab | Stage::MovingBall) {
        "grab"
    } else {
        "score"
    };
    let mut s = format!(
        "description = \"vision blackout, {name}, {preset}\"\nseed = {seed}\n\n\
         [run]\nduration_s = {dur}\nstop_at_goal = false\n\n\
         [world.field]\npreset = \"{preset}\"\n\n\
         [world.ball]\ncenter_mm = [{bx:.1}, {by:.1}]\nvelocity_mm_s = [{vx:.1}, {vy:.1}]\n\n",
        name = stage.name(),
        preset = field.preset,
        dur = stage.duration_s(),
        bx = p.ball.x,
        by = p.ball.y,
        vx = p.ball_velocity_mm_s.x,
        vy = p.ball_velocity_mm_s.y,
    );
    if let Some(d) = p.defender {
        s += &format!(
            "[[world.pillars]]\ncenter_mm = [{:.1}, {:.1}]\nradius_mm = {ROBOT_RADIUS_MM}\n\
             height_mm = 150.0\nrgb = [20, 20, 20]\n\n",
            d.x, d.y
        );
    }
    s += &format!(
        "[robot]\nstart = {{ x_mm = {:.1}, y_mm = {:.1}, heading_deg = {:.2} }}\n\
         radius_mm = {ROBOT_RADIUS_MM}\nheight_mm = 150.0\nmax_speed_mm_s = 1500.0\n\
         accel_limit_mm_s2 = 2000.0\n",
        r.x,
        r.y,
        heading.to_degrees()
    );
    if realism {
        s += "\n[robot.timing]\nframe_latency_s = 0.08\n";
    }
    s += "\n[robot.kicker]\nfront_mm = 75.0\ndribbler_width_mm = 60.0\n\n\
          [[robot.sensors]]\nname = \"omni\"\nwidth_px = 256\nheight_px = 220\nnoise_sigma = 4.0\n";
    if realism {
        s += "[robot.sensors.effects]\nexposure_s = 0.01\ndefocus_px = 1.0\n";
    }
    s += "[robot.sensors.hyperbolic]\na_mm = 12.129\nb_mm = 15.650\nc_mm = 19.8\n\
          focal_px = 479.37\nfocus_height_mm = 205.08\nrim_radius_mm = 30.0\n\n\
          [odometry]\nspeed_noise_frac = 0.03\nscale_bias_frac = 0.04\nomega_bias_rad_s = 0.01\n\n\
          [control]\nkind = \"striker\"\npose_source = \"localization\"\n\n[control.striker]\n";
    s += &format!("task = \"{task}\"\n");
    let o = FieldSpec::from(field.kind).floor_outline();
    s += &format!(
        "\n[vision.localization.field]\na1_mm = {:?}\na2_mm = {:?}\nb_mm = {:?}\n\
         goal_half_width_mm = {:?}\nboundary_line_mm = {:?}\n",
        o.a1_mm, o.a2_mm, o.b_mm, o.goal_half_width_mm, o.boundary_line_mm
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placements_keep_the_rules() {
        for field in [HARDWARE_CHALLENGE, DIVISION_B] {
            for seed in 0..50 {
                for stage in Stage::ALL {
                    let p = place(stage, &field, seed);
                    assert!(field.inside(p.robot.0, 0.0), "{stage:?} {p:?}");
                    assert!(field.inside(p.ball, 0.0), "{stage:?} {p:?}");
                    assert!(!field.in_defense_area(p.robot.0, ROBOT_RADIUS_MM));
                    if stage == Stage::Defended {
                        assert!(p.robot.0.x >= 0.0);
                        assert!(field.in_defense_area(p.defender.unwrap(), -ROBOT_RADIUS_MM));
                    }
                    if stage == Stage::MovingBall {
                        let d = (p.ball - p.robot.0).norm();
                        assert!((3000.0..5000.0).contains(&d), "{d}");
                        let v = p.ball_velocity_mm_s;
                        assert!((2000.0..6500.0).contains(&v.norm()));
                        // The straight path passes within 0.5 m of the robot.
                        let to = p.robot.0 - p.ball;
                        let across = (to.x * v.y - to.y * v.x).abs() / v.norm();
                        assert!(across <= 500.0 && to.dot(&v) > 0.0, "{across}");
                    }
                }
            }
        }
        assert_ne!(
            place(Stage::Grab, &HARDWARE_CHALLENGE, 1),
            place(Stage::Grab, &HARDWARE_CHALLENGE, 2)
        );
    }

    #[test]
    fn a_body_touches_the_defense_area_by_its_distance_round_the_corner() {
        let f = HARDWARE_CHALLENGE;
        // The +x area's corner at (1200, 1000): 92.7 mm off diagonally, clear of a 90 mm body
        // though inside the area's rectangle grown by 90 mm.
        let p = Point2::new(1115.0, 1037.0);
        assert!(f.in_defense_area(p, ROBOT_RADIUS_MM));
        assert!(!f.body_touches_defense_area(p, ROBOT_RADIUS_MM));
        assert!(f.body_touches_defense_area(Point2::new(1125.0, 1030.0), ROBOT_RADIUS_MM));
        // Straight in front of the line, and at the -x area.
        assert!(f.body_touches_defense_area(Point2::new(1111.0, 0.0), ROBOT_RADIUS_MM));
        assert!(!f.body_touches_defense_area(Point2::new(-1109.0, 0.0), ROBOT_RADIUS_MM));
        assert!(f.body_touches_defense_area(Point2::new(-1500.0, -200.0), ROBOT_RADIUS_MM));
    }
}

#[cfg(test)]
mod figures {
    use super::*;
    use omniloop_sim::FieldSpec;

    #[test]
    fn the_fields_are_the_scenario_presets() {
        for f in [HARDWARE_CHALLENGE, DIVISION_B] {
            let spec: FieldSpec = toml::from_str(&format!("preset = \"{}\"", f.preset)).unwrap();
            assert_eq!(spec.half_length_mm, f.half_length_mm, "{}", f.preset);
            assert_eq!(spec.half_width_mm, f.half_width_mm);
            assert_eq!(spec.goal_width_mm, f.goal_width_mm);
            assert_eq!(spec.defense_area_depth_mm, f.defense_mm[0]);
            assert_eq!(spec.defense_area_width_mm, f.defense_mm[1]);
        }
    }
}
