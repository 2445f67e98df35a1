//! A driving run stepped from outside, one control cycle at a time: what the Python package's
//! `Simulation` and Gymnasium environments, or any tool that owns the loop, drive.
//!
//! A [`Session`] senses ahead: once built, and after every [`Session::step`], the frames of
//! the coming cycle are rendered, so the outside can read them before it decides. The cycles
//! it runs are those of `omniloop run` (the same renders, commands and physics in the same
//! order), so a session of the built-in robot stepped to its end leaves the same
//! `trajectory.csv`, byte for byte.

use super::experiment::{Drive, Experiment};
use super::registry::setup_of;
use crate::run::{RunError, RunOptions, RunOutput, Simulation};
use crate::scenario::Scenario;
use omniloop_robot::{RobotConfig, RobotError, RobotSoftware};
use std::time::Instant;

/// A driving run stepped from outside (see the module's documentation).
///
/// The built-in robot drives the corner for a few cycles; between steps the outside reads the
/// frames its software got and the truth:
///
/// ```
/// use omniloop::run::builtin_software;
/// use omniloop::vision::FreeSpace;
/// use omniloop::{RunOptions, Session, load_scenario};
/// use omniloop_sim::RendererChoice;
///
/// # fn main() -> anyhow::Result<()> {
/// let scenario = load_scenario("scenarios/corner55_velocity_aware.toml".as_ref())?;
/// let options = RunOptions {
///     renderer: RendererChoice::Cpu,
///     ..RunOptions::default()
/// };
/// let mut session = Session::new(&scenario, &options, builtin_software, |_| {})?;
/// for _ in 0..10 {
///     let frames = session.simulation().frames();
///     assert_eq!(frames.len(), 1, "the corner's robot has one camera");
///     session.step()?;
/// }
/// let truth = session.simulation().truth();
/// assert!(truth.pose.translation.x > -2500.0, "it drove forward from its start");
/// let output = session.output();
/// assert_eq!(output.summary.cycles, 10);
/// assert!(output.estimates[9].percept::<FreeSpace>().is_some(), "it saw free space");
/// # Ok(())
/// # }
/// ```
pub struct Session {
    sim: Simulation,
    experiment: Box<dyn Experiment>,
    started: Instant,
    /// Seconds spent in control cycles (sensing included).
    loop_s: f64,
}

impl Session {
    /// Builds the run of a validated scenario with the robot's software that `software`
    /// builds, and senses the first cycle's frames. A scenario whose experiment runs a
    /// procedure of its own (carrying the robot between places, taking its own frames) cannot
    /// be stepped from outside: run it whole ([`crate::Runner`]).
    pub fn new(
        scenario: &Scenario,
        options: &RunOptions,
        software: impl FnMut(&RobotConfig) -> Result<Box<dyn RobotSoftware>, RobotError>,
        notice: impl FnOnce(&str),
    ) -> Result<Self, RunError> {
        let started = Instant::now();
        let setup = setup_of(scenario).map_err(|p| RunError::Scenario(p.to_string()))?;
        let experiment = match &setup {
            Some(e) => e.procedure(scenario)?,
            None => Box::new(Drive),
        };
        if !experiment.drives() {
            return Err(RunError::Scenario(format!(
                "scenario {:?}: its experiment `{}` runs a procedure of its own (it moves the \
                 robot or takes its own frames), so it cannot be stepped from outside; run it \
                 whole (`omniloop run`, `omniloop.run`)",
                scenario.name,
                scenario.experiment_name().unwrap_or_default()
            )));
        }
        let mut sim = Simulation::with_software(scenario, options, software, notice)?;
        let t = Instant::now();
        sim.sense()?;
        Ok(Self {
            sim,
            experiment,
            started,
            loop_s: t.elapsed().as_secs_f64(),
        })
    }

    /// The simulation (its truth, frames, robot software).
    pub fn simulation(&self) -> &Simulation {
        &self.sim
    }

    /// The simulation, to reach the robot's software.
    pub fn simulation_mut(&mut self) -> &mut Simulation {
        &mut self.sim
    }

    /// Whether the run is over (time up, or the goal reached where the run stops there).
    pub fn finished(&self) -> bool {
        self.sim.finished()
    }

    /// One control cycle on the frames sensed last: the robot's software decides, the world
    /// moves on one period; then the next cycle's frames are sensed (also at the end, so the
    /// last state can be seen). The run's final state is recorded when it ends.
    pub fn step(&mut self) -> Result<(), RunError> {
        if self.sim.finished() {
            return Err(RunError::Finished {
                scenario: self.sim.scenario().name.clone(),
                cycles: self.sim.cycle(),
            });
        }
        let t = Instant::now();
        self.sim.act()?;
        if self.sim.finished() {
            self.sim.record_final_state();
        }
        self.sim.sense()?;
        self.loop_s += t.elapsed().as_secs_f64();
        Ok(())
    }

    /// Everything recorded so far, as [`crate::Runner::run`] gives it at the end: the summary
    /// with the experiment's metrics and the records (the experiment's files are
    /// [`Session::output_with_files`]'s: drawing them is not needed for a summary).
    pub fn output(&self) -> RunOutput {
        let mut out = self.sim.output(self.started.elapsed().as_secs_f64());
        if self.loop_s > 0.0 {
            out.summary.cycles_per_s = out.summary.cycles as f64 / self.loop_s;
        }
        out.summary.experiment = self.experiment.metrics(&out);
        out
    }

    /// [`Session::output`] with the experiment's own files (tables, figures), to write.
    pub fn output_with_files(&self) -> Result<RunOutput, RunError> {
        let mut out = self.output();
        out.files = self.experiment.files(self.sim.scenario(), &out)?;
        Ok(out)
    }
}
