//! A robot of your own: a gap follower on dead reckoning and the free space `omniloop::vision`
//! finds. It heads for the free direction nearest the goal's whose corridor (the body's width)
//! is open far enough, at the speed from which it can still stop (v = sqrt(2 a d)), e.g.
//! `cargo run --release --example custom_robot -- scenarios/corner55_velocity_aware.toml`

use anyhow::Context;
use nalgebra::{Isometry2, Rotation2, Vector2};
use omniloop::control::{DeadReckoning, wrap_pi};
use omniloop::robot::*; // RobotSoftware, Observation, Outputs, RobotConfig, ...
use omniloop::vision::{FreeSpace, FreeSpaceDetector};
use omniloop::{Runner, Summary, load_scenario, report::write_run};

const LOOKAHEAD_MM: f64 = 450.0; // how far the chosen corridor must be open
const MARGIN_MM: f64 = 90.0; // the gap kept between body and obstacles

struct GapFollower {
    camera: String,
    detector: FreeSpaceDetector,
    start: Isometry2<f64>,
    odometry: DeadReckoning,
    goal: Vector2<f64>,
    body: BodySpec,
}

impl GapFollower {
    fn new(c: &RobotConfig) -> Result<Self, RobotError> {
        let missing = |what: &str| RobotError::Missing(format!("the gap follower needs {what}"));
        let camera = c.vision_camera().ok_or_else(|| missing("a camera"))?;
        let cal = c.calibration(camera).ok_or_else(|| missing("a mirror"))?;
        let goal = c.goal.as_ref().ok_or_else(|| missing("a [goal]"))?.point();
        Ok(Self {
            detector: FreeSpaceDetector::new(c.vision.table("freespace")?, cal)?,
            camera: camera.to_string(),
            start: c.start,
            odometry: DeadReckoning::new(),
            goal: goal.coords,
            body: c.body,
        })
    }

    /// The free distance along direction `j`: the least over those its corridor overlaps.
    fn corridor_mm(&self, fs: &FreeSpace, j: usize) -> f64 {
        let n = fs.free_mm.len() as isize;
        let half = ((self.body.radius_mm + MARGIN_MM) / LOOKAHEAD_MM).asin();
        let k = (half * n as f64 / std::f64::consts::TAU).ceil() as isize;
        let free = |d: isize| fs.free_mm[(j as isize + d).rem_euclid(n) as usize];
        (-k..=k).map(free).fold(f64::INFINITY, f64::min)
    }

    fn decide(&self, fs: &FreeSpace, pose: &Isometry2<f64>) -> Vector2<f64> {
        let to_goal = pose.inverse_transform_vector(&(self.goal - pose.translation.vector));
        let (distance, heading) = (to_goal.norm(), to_goal.y.atan2(to_goal.x));
        let need = LOOKAHEAD_MM.min(distance) + self.body.radius_mm;
        let off = |j: &usize| wrap_pi(fs.direction_rad[*j] - heading).abs();
        let open = (0..fs.free_mm.len()).filter(|&j| self.corridor_mm(fs, j) >= need);
        let Some(j) = open.min_by(|a, b| off(a).total_cmp(&off(b))) else {
            return Vector2::zeros();
        };
        let room = self.corridor_mm(fs, j) - self.body.radius_mm - MARGIN_MM;
        let v = (2.0 * self.body.accel_limit_mm_s2 * room.min(distance).max(0.0)).sqrt();
        Rotation2::new(fs.direction_rad[j]) * Vector2::x() * v.min(self.body.max_speed_mm_s)
    }
}

impl RobotSoftware for GapFollower {
    fn cameras(&self) -> Vec<String> {
        vec![self.camera.clone()]
    }

    fn cycle(&mut self, obs: &Observation<'_>) -> Result<Outputs, RobotError> {
        let fs = self.detector.detect(obs.image(&self.camera, "gap")?)?;
        let pose = self.start * self.odometry.pose();
        let command = BodyCommand::translate(self.decide(&fs, &pose));
        let mut beliefs = Estimates::at(obs.t_s);
        beliefs.pose = Some(pose);
        beliefs.percepts.put(fs);
        Ok(Outputs::drive(command, beliefs))
    }

    fn odometry(&mut self, r: &OdometryReading) {
        self.odometry.update(r.v_body_mm_s, r.omega_rad_s, r.dt_s);
    }
}

/// Runs `scenario` with the gap follower and writes the run's files into `out`.
pub fn run(scenario: &std::path::Path, out: &std::path::Path) -> anyhow::Result<Summary> {
    let scenario = load_scenario(scenario)?;
    let output = Runner::new(&scenario).software(GapFollower::new).run()?;
    write_run(out, &scenario, &output)?;
    Ok(output.summary)
}

fn main() -> anyhow::Result<()> {
    let path = std::env::args().nth(1).context("usage: SCENARIO.toml")?;
    let s = run(path.as_ref(), "runs/custom_robot".as_ref())?;
    let (goal, contacts) = (s.reached_goal, s.wall_contacts);
    println!("reached goal: {goal}, contacts: {contacts}");
    Ok(())
}
