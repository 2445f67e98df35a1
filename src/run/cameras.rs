//! The robot's cameras on the simulator's side: the renderer, each camera's optics and seeded
//! noise, and the pan units of pinhole cameras, which the robot commands.

use super::error::RunError;
use super::truth_files;
use crate::scenario::Scenario;
use crate::scenario::TimingSpec;
use image::RgbaImage;
use omniloop_robot::{ActuatorCommand, ActuatorState, Frame};
use omniloop_sim::optics::Optics;
use omniloop_sim::render::effects::{exposure_poses, pose_after};
use omniloop_sim::render::{BatchHandle, TruthFrame};
use omniloop_sim::{Renderer, RendererChoice, RobotState, Scene, Sensor, SensorNoise, World};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use std::collections::VecDeque;
use std::f64::consts::PI;

/// The seed of sensor `index`'s noise, derived from the run's seed.
pub fn sensor_noise_seed(seed: u64, index: usize) -> u64 {
    seed ^ (index as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15)
}

/// A pan unit: turns its camera about the vertical at up to its rate limit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PanUnit {
    pan_rad: f64,
    limit_rad_s: f64,
    goal: PanGoal,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum PanGoal {
    Hold,
    To(f64),
    At(f64),
}

impl PanUnit {
    /// A unit at `pan_rad` turning at most `limit_rad_s`.
    pub fn new(pan_rad: f64, limit_rad_s: f64) -> Self {
        Self {
            pan_rad,
            limit_rad_s,
            goal: PanGoal::Hold,
        }
    }

    /// The pan angle, rad, within [-pi, pi].
    pub fn pan_rad(&self) -> f64 {
        self.pan_rad
    }

    /// Turn toward `pan_rad` (clamped to [-pi, pi]; the unit turns through its front, never
    /// across the cable stop at the back).
    pub fn pan_to(&mut self, pan_rad: f64) {
        self.goal = PanGoal::To(pan_rad.clamp(-PI, PI));
    }

    /// Turn at `rate_rad_s` (clipped to the limit) until the stop or told otherwise.
    pub fn pan_at(&mut self, rate_rad_s: f64) {
        self.goal = PanGoal::At(rate_rad_s.clamp(-self.limit_rad_s, self.limit_rad_s));
    }

    /// Moves the unit on by `dt_s`.
    pub fn advance(&mut self, dt_s: f64) {
        let step = self.limit_rad_s * dt_s;
        self.pan_rad = match self.goal {
            PanGoal::Hold => self.pan_rad,
            PanGoal::To(t) => self.pan_rad + (t - self.pan_rad).clamp(-step, step),
            PanGoal::At(rate) => (self.pan_rad + rate * dt_s).clamp(-PI, PI),
        };
    }
}

/// `sensor` with its pinhole camera turned to `pan_rad` on its pan unit.
fn turned_to(sensor: &Sensor, pan_rad: f64) -> Sensor {
    let mut s = sensor.clone();
    if let Optics::Pinhole(cam) = &mut s.optics {
        cam.pan_deg = pan_rad.to_degrees();
    }
    s
}

struct Camera {
    sensor: Sensor,
    noise: SensorNoise,
    pan: Option<PanUnit>,
    /// Whether it is rendered each cycle.
    live: bool,
}

/// The robot's cameras and the renderer that traces their images.
pub struct Cameras {
    renderer: Renderer,
    cameras: Vec<Camera>,
    /// The capture the software gets now, one entry a camera (`None`: not rendered, lost or
    /// not yet arrived).
    images: Vec<Option<RgbaImage>>,
    /// When that capture was taken.
    images_t_s: f64,
    /// When frames arrive and how many are lost.
    delivery: Delivery,
    /// Captures on their way to the software.
    queue: VecDeque<Capture>,
    /// Whether each frame's truth is traced beside it (the simulator's side only).
    keep_truth: bool,
    /// The truth of each frame of the capture the software gets now.
    truth: Vec<Option<TruthFrame>>,
}

/// A capture on its way: when it was taken, the cycle it arrives, its frames and their truth.
struct Capture {
    t_s: f64,
    arrives_s: f64,
    images: Vec<Option<RgbaImage>>,
    truth: Vec<Option<TruthFrame>>,
}

/// `[robot.timing]`'s frame latency as whole control periods `periods` plus the capture's
/// place in its period, and the seeded loss of frames.
struct Delivery {
    /// Periods between the cycle that renders a frame and the one that gets it.
    periods: u32,
    /// How far into its cycle a frame is taken (s): `periods * dt - latency`.
    offset_s: f64,
    period_s: f64,
    drop_rate: f64,
    rng: StdRng,
}

impl Delivery {
    fn new(timing: &TimingSpec, control_period_s: f64, seed: u64) -> Self {
        let periods = (timing.frame_latency_s / control_period_s - 1e-9)
            .ceil()
            .max(0.0);
        Self {
            periods: periods as u32,
            offset_s: (periods * control_period_s - timing.frame_latency_s).max(0.0),
            period_s: control_period_s,
            drop_rate: timing.frame_drop_rate,
            rng: StdRng::seed_from_u64(seed ^ 0xD50F_F2A3_E000_0001),
        }
    }

    /// Whether the next frame is lost (no draw when none is).
    fn lost(&mut self) -> bool {
        self.drop_rate > 0.0 && self.rng.random::<f64>() < self.drop_rate
    }
}

impl Cameras {
    /// The cameras of the robot under test, rendering those called in `wanted` (or all with
    /// `all`); `None` when nothing is to be rendered.
    pub fn open(
        scenario: &Scenario,
        wanted: &[String],
        all: bool,
        choice: RendererChoice,
        shared: Option<&BatchHandle>,
        notice: impl FnOnce(&str),
    ) -> Result<Option<Self>, RunError> {
        let specs = &scenario.robot.sensors;
        if specs.is_empty() || (wanted.is_empty() && !all) {
            return Ok(None);
        }
        let mut cameras = Vec::with_capacity(specs.len());
        for (i, spec) in specs.iter().enumerate() {
            let pan = spec
                .optics
                .pinhole()
                .map(|p| PanUnit::new(p.pan_deg.to_radians(), p.pan_rate_limit_deg_s.to_radians()));
            cameras.push(Camera {
                sensor: spec.build(),
                noise: SensorNoise::new(sensor_noise_seed(scenario.seed, i)),
                pan,
                live: all || wanted.contains(&spec.name),
            });
        }
        Ok(Some(Self {
            renderer: match shared {
                Some(server) => Renderer::shared(server),
                None => Renderer::new(choice, notice)?,
            },
            cameras,
            images: Vec::new(),
            images_t_s: 0.0,
            delivery: Delivery::new(
                &scenario.robot.timing,
                scenario.run.control_period_s,
                scenario.seed,
            ),
            queue: VecDeque::new(),
            keep_truth: false,
            truth: Vec::new(),
        }))
    }

    /// Traces each frame's truth beside it from now on ([`Cameras::truth`]).
    pub fn keep_truth(&mut self) {
        self.keep_truth = true;
    }

    /// Whether each frame's truth is traced beside it.
    pub fn keeps_truth(&self) -> bool {
        self.keep_truth
    }

    /// The renderer's name.
    pub fn renderer_name(&self) -> &str {
        self.renderer.name()
    }

    /// Renders every live camera of robot `body` of `world` at its true pose, with its noise.
    pub fn capture(&mut self, world: &World, body: usize) -> Result<(), RunError> {
        let scene = Scene::of_world(world);
        self.capture_some(&scene, world.robot_state(body), world.time_s(), None)
    }

    /// Renders the live cameras named in `wanted` (all live ones with `None`) in `scene` at
    /// `now`, the robot that carries them in `state` (its true pose and velocity), with their
    /// noise; the others give no frame this cycle. With a frame latency, the frames rendered
    /// now arrive that much later (taken `offset_s` into this cycle, the robot moved on along
    /// its velocity and the pan units on toward their goals; the rest of the world as at the
    /// cycle's start), and the capture that arrives now is the one the software gets; a lost
    /// frame never arrives.
    pub fn capture_some(
        &mut self,
        scene: &Scene,
        mut state: RobotState,
        now: f64,
        wanted: Option<&[String]>,
    ) -> Result<(), RunError> {
        let offset = self.delivery.offset_s;
        state.pose = pose_after(&state.pose, state.velocity_mm_s, state.omega_rad_s, offset);
        let mut images = Vec::with_capacity(self.cameras.len());
        let mut truth = Vec::with_capacity(self.cameras.len());
        for c in &mut self.cameras {
            let take = c.live && wanted.is_none_or(|w| w.contains(&c.sensor.name));
            let img = if take && !self.delivery.lost() {
                let poses = exposure_poses(
                    &state.pose,
                    state.velocity_mm_s,
                    state.omega_rad_s,
                    &c.sensor.effects,
                );
                let turned = c.pan.filter(|_| offset > 0.0).map(|mut unit| {
                    unit.advance(offset);
                    turned_to(&c.sensor, unit.pan_rad())
                });
                let sensor = turned.as_ref().unwrap_or(&c.sensor);
                let noise = Some(&mut c.noise);
                if self.keep_truth {
                    let (img, t) =
                        (self.renderer).render_exposed_truth(scene, sensor, &poses, noise)?;
                    truth.push(Some(t));
                    Some(img)
                } else {
                    truth.push(None);
                    Some(self.renderer.render_exposed(scene, sensor, &poses, noise)?)
                }
            } else {
                truth.push(None);
                None
            };
            images.push(img);
        }
        self.queue.push_back(Capture {
            t_s: now + offset,
            arrives_s: now + f64::from(self.delivery.periods) * self.delivery.period_s,
            images,
            truth,
        });
        self.images = vec![None; self.cameras.len()];
        self.truth = vec![None; self.cameras.len()];
        while let Some(first) = self.queue.front() {
            if first.arrives_s > now + 1e-9 {
                break;
            }
            let Some(arrived) = self.queue.pop_front() else {
                break;
            };
            self.images = arrived.images;
            self.truth = arrived.truth;
            self.images_t_s = arrived.t_s;
        }
        Ok(())
    }

    /// The frames the software gets now, by camera name, stamped with the time they were
    /// taken.
    pub fn frames(&self) -> Vec<Frame<'_>> {
        let t_s = self.images_t_s;
        self.cameras
            .iter()
            .zip(&self.images)
            .filter_map(|(c, image)| {
                image.as_ref().map(|image| Frame {
                    sensor: &c.sensor.name,
                    t_s,
                    image,
                })
            })
            .collect()
    }

    /// The truth of the frame of camera `name` the software gets now, when the truth is kept
    /// (the simulator's side: for scoring and recording, never for the software).
    pub fn truth(&self, name: &str) -> Option<&TruthFrame> {
        (self.cameras.iter().zip(&self.truth))
            .find(|(c, _)| c.sensor.name == name)
            .and_then(|(_, t)| t.as_ref())
    }

    /// The truth of every frame the software gets now, by camera name.
    pub fn truth_frames(&self) -> Vec<(&str, &TruthFrame)> {
        (self.cameras.iter().zip(&self.truth))
            .filter_map(|(c, t)| t.as_ref().map(|t| (c.sensor.name.as_str(), t)))
            .collect()
    }

    /// The last capture of camera `name`, if it was rendered.
    pub fn image(&self, name: &str) -> Option<&RgbaImage> {
        self.cameras
            .iter()
            .zip(&self.images)
            .find(|(c, _)| c.sensor.name == name)
            .and_then(|(_, image)| image.as_ref())
    }

    /// The state of the pan units.
    pub fn actuator_state(&self) -> Vec<ActuatorState> {
        self.cameras
            .iter()
            .filter_map(|c| {
                c.pan.map(|p| ActuatorState::Pan {
                    sensor: c.sensor.name.clone(),
                    pan_rad: p.pan_rad(),
                })
            })
            .collect()
    }

    /// Passes the robot's actuator commands to the pan units (the kicker's go to the world).
    pub fn command(&mut self, commands: &[ActuatorCommand]) -> Result<(), RunError> {
        for cmd in commands {
            let (ActuatorCommand::PanTo { sensor, .. } | ActuatorCommand::PanAt { sensor, .. }) =
                cmd
            else {
                continue;
            };
            let unit = self
                .cameras
                .iter_mut()
                .find(|c| c.sensor.name == *sensor)
                .and_then(|c| c.pan.as_mut())
                .ok_or_else(|| {
                    RunError::Actuator(format!(
                        "the robot commanded a pan of camera {sensor:?}, which is not on a pan \
                         unit (only pinhole cameras are)"
                    ))
                })?;
            match *cmd {
                ActuatorCommand::PanTo { pan_rad, .. } => unit.pan_to(pan_rad),
                ActuatorCommand::PanAt { rate_rad_s, .. } => unit.pan_at(rate_rad_s),
                _ => {}
            }
        }
        Ok(())
    }

    /// Moves the pan units on by `dt_s` and turns their cameras.
    pub fn advance(&mut self, dt_s: f64) {
        for c in &mut self.cameras {
            if let (Some(unit), Optics::Pinhole(cam)) = (&mut c.pan, &mut c.sensor.optics) {
                unit.advance(dt_s);
                cam.pan_deg = unit.pan_rad().to_degrees();
            }
        }
    }

    /// Writes the last capture to `dir` as `<camera>_<cycle>.png`, with its truth where kept
    /// (`<camera>_<cycle>_depth.png`, `_labels.png`, and the folder's `legend.json` once).
    pub fn save(&self, dir: &std::path::Path, cycle: u64) -> Result<(), RunError> {
        for (k, (c, img)) in self.cameras.iter().zip(&self.images).enumerate() {
            let Some(img) = img else { continue };
            let stem = format!("{}_{:06}", c.sensor.name, cycle);
            let path = dir.join(format!("{stem}.png"));
            img.save(&path)
                .map_err(|reason| RunError::Frame { path, reason })?;
            if let Some(truth) = self.truth.get(k).and_then(Option::as_ref) {
                truth_files::write_truth(dir, &stem, truth)?;
                let legend = dir.join("legend.json");
                if !legend.exists() {
                    truth_files::write_legend(&legend, truth)?;
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pan_unit_turns_at_its_rate_limit_and_stops_at_its_ends() {
        let mut u = PanUnit::new(0.0, 60f64.to_radians());
        u.pan_to(90f64.to_radians());
        for _ in 0..25 {
            u.advance(0.04);
        }
        // One second at 60 deg/s.
        assert!((u.pan_rad().to_degrees() - 60.0).abs() < 1e-9);
        for _ in 0..25 {
            u.advance(0.04);
        }
        assert!(
            (u.pan_rad().to_degrees() - 90.0).abs() < 1e-9,
            "reaches, no overshoot"
        );
        // Clipped to 60 deg/s: 270 degrees take 4.5 s.
        u.pan_at(-10.0);
        for _ in 0..120 {
            u.advance(0.04);
        }
        assert!((u.pan_rad() + PI).abs() < 1e-12, "stops at -180 degrees");
        u.pan_to(4.0);
        assert_eq!(u.goal, PanGoal::To(PI));
    }
}
