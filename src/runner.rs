//! Running a scenario with any robot software: the library's way in for a user's robot.

use crate::scenario::Scenario;
use crate::simulation::{RunError, RunOptions, RunOutput, builtin_software, run_scenario_with};
use omniloop_robot::{RobotConfig, RobotError, RobotSoftware};
use omniloop_sim::RendererChoice;

/// Builds the robot's software from what the robot is told.
type SoftwareFactory<'a> =
    Box<dyn FnOnce(&RobotConfig) -> Result<Box<dyn RobotSoftware>, RobotError> + 'a>;

/// A run of a scenario, set up step by step: the robot's software (the built-in stack unless
/// told otherwise), the renderer, the seed, a progress callback.
///
/// ```no_run
/// use omniloop::{Runner, load_scenario};
/// use omniloop::robot::{BodyCommand, Estimates, Observation, OdometryReading, Outputs};
/// use omniloop::robot::{RobotError, RobotSoftware};
///
/// /// Drives straight ahead at 200 mm/s and reads no camera.
/// struct Straight;
///
/// impl RobotSoftware for Straight {
///     fn cameras(&self) -> Vec<String> {
///         Vec::new()
///     }
///     fn cycle(&mut self, obs: &Observation<'_>) -> Result<Outputs, RobotError> {
///         Ok(Outputs {
///             command: BodyCommand::translate([200.0, 0.0].into()),
///             actuators: Vec::new(),
///             estimates: Estimates { t_s: obs.t_s, ..Estimates::default() },
///         })
///     }
///     fn odometry(&mut self, _reading: &OdometryReading) {}
/// }
///
/// # fn main() -> anyhow::Result<()> {
/// let scenario = load_scenario("scenarios/corner55_velocity_aware.toml".as_ref())?;
/// let output = Runner::new(&scenario).software(|_config| Ok(Straight)).run()?;
/// println!("reached the goal: {}", output.summary.reached_goal);
/// # Ok(())
/// # }
/// ```
pub struct Runner<'a> {
    scenario: Scenario,
    options: RunOptions,
    software: SoftwareFactory<'a>,
    progress: Box<dyn FnMut(u64, u64) + 'a>,
    notice: Box<dyn FnOnce(&str) + 'a>,
}

impl<'a> Runner<'a> {
    /// A run of a validated scenario (see [`crate::load_scenario`]) with the built-in robot
    /// software, the renderer chosen automatically, the scenario's seed, no progress shown.
    pub fn new(scenario: &Scenario) -> Self {
        Self {
            scenario: scenario.clone(),
            options: RunOptions::default(),
            software: Box::new(builtin_software),
            progress: Box::new(|_, _| {}),
            notice: Box::new(|_| {}),
        }
    }

    /// Runs the robot software that `build` makes from what the robot is told (its start,
    /// body, cameras with their calibrations, goal and map; never the world).
    pub fn software<R: RobotSoftware + 'static>(
        mut self,
        build: impl FnOnce(&RobotConfig) -> Result<R, RobotError> + 'a,
    ) -> Self {
        self.software = Box::new(move |config: &RobotConfig| {
            build(config).map(|r| Box::new(r) as Box<dyn RobotSoftware>)
        });
        self
    }

    /// Renders with this renderer (default: `auto`).
    pub fn renderer(mut self, choice: RendererChoice) -> Self {
        self.options.renderer = choice;
        self
    }

    /// Runs with this seed instead of the scenario's.
    pub fn seed(mut self, seed: u64) -> Self {
        self.scenario.seed = seed;
        self
    }

    /// All run options at once (renderer, saved frames, a shared GPU).
    pub fn options(mut self, options: RunOptions) -> Self {
        self.options = options;
        self
    }

    /// Calls `progress(cycle, total)` as the run goes.
    pub fn progress(mut self, progress: impl FnMut(u64, u64) + 'a) -> Self {
        self.progress = Box::new(progress);
        self
    }

    /// Receives one-line notices for the user (the renderer's choice).
    pub fn notice(mut self, notice: impl FnOnce(&str) + 'a) -> Self {
        self.notice = Box::new(notice);
        self
    }

    /// The scenario as it will run.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// Runs the scenario to its end by its experiment's procedure.
    pub fn run(self) -> Result<RunOutput, RunError> {
        run_scenario_with(
            &self.scenario,
            &self.options,
            self.software,
            self.notice,
            self.progress,
        )
    }
}
