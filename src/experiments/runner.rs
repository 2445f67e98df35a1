//! Running a scenario by its experiment's procedure, with the built-in robot software or any
//! other ([`Runner`]: the library's way in for a user's robot), and loading scenario files
//! with every experiment's own checks.

use super::experiment::Drive;
use super::registry::{self, setup_of};
use crate::run::{RunError, RunOptions, RunOutput, Simulation, builtin_software};
use crate::scenario::{LoadError, Scenario};
use omniloop_robot::{RobotConfig, RobotError, RobotSoftware};
use omniloop_sim::RendererChoice;
use std::path::Path;
use std::time::Instant;

/// Builds a robot's software from what the robot is told.
type SoftwareFactory<'a> =
    Box<dyn FnMut(&RobotConfig) -> Result<Box<dyn RobotSoftware>, RobotError> + 'a>;

/// A run of a scenario, set up step by step: the robot's software (the built-in stack unless
/// told otherwise), the renderer, the seed, a progress callback.
///
/// ```
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
/// // Straight ahead from the corridor's start runs into its wall before the goal.
/// assert!(!output.summary.reached_goal);
/// assert!(output.summary.wall_contacts > 0);
/// # Ok(())
/// # }
/// ```
pub struct Runner<'a> {
    scenario: Scenario,
    options: RunOptions,
    software: SoftwareFactory<'a>,
    /// Software for robots of a team by name, over `software`.
    named: Vec<(String, SoftwareFactory<'a>)>,
    progress: Box<dyn FnMut(u64, u64) + 'a>,
    notice: Box<dyn FnOnce(&str) + 'a>,
}

impl<'a> Runner<'a> {
    /// A run of a validated scenario (see [`load_scenario`]) with the built-in robot
    /// software, the renderer chosen automatically, the scenario's seed, no progress shown.
    pub fn new(scenario: &Scenario) -> Self {
        Self {
            scenario: scenario.clone(),
            options: RunOptions::default(),
            software: Box::new(builtin_software),
            named: Vec::new(),
            progress: Box::new(|_, _| {}),
            notice: Box::new(|_| {}),
        }
    }

    /// Runs the robot software that `build` makes from what the robot is told (its name,
    /// start, body, cameras with their calibrations, goal and map; never the world): on every
    /// robot of a team that [`Runner::software_for`] does not name.
    pub fn software<R: RobotSoftware + 'static>(
        mut self,
        mut build: impl FnMut(&RobotConfig) -> Result<R, RobotError> + 'a,
    ) -> Self {
        self.software = Box::new(move |config: &RobotConfig| {
            build(config).map(|r| Box::new(r) as Box<dyn RobotSoftware>)
        });
        self
    }

    /// Runs the software `build` makes on the robot of the team called `robot` (the others
    /// keep the built-in stack, or [`Runner::software`]'s); a name that is no robot's fails
    /// the run before it starts.
    pub fn software_for<R: RobotSoftware + 'static>(
        mut self,
        robot: &str,
        mut build: impl FnMut(&RobotConfig) -> Result<R, RobotError> + 'a,
    ) -> Self {
        self.named.push((
            robot.to_string(),
            Box::new(move |config: &RobotConfig| {
                build(config).map(|r| Box::new(r) as Box<dyn RobotSoftware>)
            }),
        ));
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
        let names = self.scenario.robot_names();
        for (name, _) in &self.named {
            if !names.contains(name) {
                return Err(RunError::Team(format!(
                    "software for robot {name:?}: scenario {:?} has no robot of that name (its \
                     robots: {})",
                    self.scenario.name,
                    names.join(", ")
                )));
            }
        }
        let (mut software, mut named) = (self.software, self.named);
        let build =
            move |config: &RobotConfig| match named.iter_mut().find(|(n, _)| *n == config.name) {
                Some((_, f)) => f(config),
                None => software(config),
            };
        run_scenario_with(
            &self.scenario,
            &self.options,
            build,
            self.notice,
            self.progress,
        )
    }
}

/// Runs a validated scenario to its end by its experiment's procedure (driving to the goal
/// when it names none), calling `progress(cycle, total)` along the way. The summary's
/// `wall_time_s` covers the whole run, set-up included (calibration, opening the renderer);
/// its `cycles_per_s` covers the control cycles alone.
pub fn run_scenario(
    scenario: &Scenario,
    options: &RunOptions,
    notice: impl FnOnce(&str),
    progress: impl FnMut(u64, u64),
) -> Result<RunOutput, RunError> {
    run_scenario_with(scenario, options, builtin_software, notice, progress)
}

/// [`run_scenario`] with the robot's software that `software` builds.
pub fn run_scenario_with(
    scenario: &Scenario,
    options: &RunOptions,
    software: impl FnMut(&RobotConfig) -> Result<Box<dyn RobotSoftware>, RobotError>,
    notice: impl FnOnce(&str),
    mut progress: impl FnMut(u64, u64),
) -> Result<RunOutput, RunError> {
    let start = Instant::now();
    let setup = setup_of(scenario).map_err(|p| RunError::Scenario(p.to_string()))?;
    let mut options = options.clone();
    options.takes_frames |= setup.as_ref().is_some_and(|e| e.takes_frames());
    let mut sim = Simulation::with_software(scenario, &options, software, notice)?;
    let mut experiment = match &setup {
        Some(e) => e.procedure(scenario)?,
        None => Box::new(Drive),
    };
    let loop_start = Instant::now();
    experiment.run(&mut sim, &mut progress)?;
    let loop_s = loop_start.elapsed().as_secs_f64();
    let mut out = sim.finish(start.elapsed().as_secs_f64());
    if loop_s > 0.0 {
        out.summary.cycles_per_s = out.summary.cycles as f64 / loop_s;
    }
    out.summary.experiment = experiment.metrics(&out);
    out.files = experiment.files(scenario, &out)?;
    Ok(out)
}

/// [`run_scenario`] with its callbacks as trait objects (the replays' runner).
pub fn run_dyn(
    scenario: &Scenario,
    options: &RunOptions,
    notice: &mut dyn FnMut(&str),
    progress: &mut dyn FnMut(u64, u64),
) -> Result<RunOutput, RunError> {
    run_scenario(scenario, options, notice, progress)
}

/// Reads, parses and validates a scenario file, its experiment's section included (each
/// problem located by file, line, column and field). Its name defaults to the file stem.
///
/// ```
/// use omniloop::{LoadError, load_scenario, parse_scenario};
///
/// let scenario = load_scenario("scenarios/smoke.toml".as_ref())?;
/// assert_eq!(scenario.name, "smoke");
///
/// // Every problem names its file, line, column and field.
/// let text = "[world.field]\n[robot]\nstart = { x_mm = -1000.0, y_mm = 0.0 }\n\
///             [goal]\nx_mm = 1000.0\ny_mm = -5000.0\n";
/// match parse_scenario(text, "mine.toml".as_ref(), "mine") {
///     Err(LoadError::Invalid { problems }) => assert_eq!(
///         problems[0].to_string(),
///         "mine.toml:5:1: field `goal.x_mm`: goal (1000, -5000) mm is outside the floor region"
///     ),
///     other => panic!("expected a problem, got {other:?}"),
/// }
/// # Ok::<(), LoadError>(())
/// ```
pub fn load_scenario(path: &Path) -> Result<Scenario, LoadError> {
    crate::scenario::load_scenario_with(path, registry::prepare, registry::check)
}

/// Parses and validates scenario text, its experiment's section included; `file` is used in
/// messages only.
pub fn parse_scenario(text: &str, file: &Path, default_name: &str) -> Result<Scenario, LoadError> {
    crate::scenario::parse_scenario_with(
        text,
        file,
        default_name,
        registry::prepare,
        registry::check,
    )
}
