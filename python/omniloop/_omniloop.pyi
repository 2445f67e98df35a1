"""The `omniloop` Python package's native module (`omniloop._omniloop`): scenarios, whole runs,
a simulation stepped from Python with Python as the robot's software, and N of them stepped
together, the truth beside each frame and truth datasets. The pure-Python part (`omniloop/`)
adds the Gymnasium environments and the datasets' loader.

Where a method gives one robot's value for a one-robot scenario and a dict of these by robot
name for a team, its return type is ``X | Any`` (the one robot's type, checked where it is
used as such, and free where a team's dict is read).
"""

import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, Final, Union, final

import numpy as np
import numpy.typing as npt
from typing_extensions import Self, TypeAlias

from .types import Dribble, FreeSpace, Kick, PanAt, PanTo, RobotInfo, Truth, TruthFrame

_Path: TypeAlias = Union[str, os.PathLike[str]]
# One robot's command: `(vx_mm_s, vy_mm_s, omega_rad_s)` or `(v_mm_s, omega_rad_s)`.
_Command: TypeAlias = Union[Sequence[float], npt.NDArray[Any]]
# One robot's pose estimate: `(x_mm, y_mm, theta_rad)`.
_Estimate: TypeAlias = Union[Sequence[float], npt.NDArray[Any]]
_Actuators: TypeAlias = Sequence[Union[PanTo, PanAt, Kick, Dribble]]
_Columns: TypeAlias = dict[str, npt.NDArray[np.float64]]

__all__ = [
    "FreeSpaceDetector",
    "Observation",
    "Odometry",
    "RenderError",
    "RobotSoftwareError",
    "RunFinishedError",
    "RunResult",
    "Scenario",
    "ScenarioError",
    "Simulation",
    "SimulationError",
    "SweepPlan",
    "VectorSimulation",
    "__version__",
    "default_scenario",
    "read_png_levels",
    "read_png_rgb",
    "run",
    "run_planned_job",
    "sweep_plan",
    "write_dataset",
]

__version__: Final[str]

class ScenarioError(ValueError):
    """A scenario file or text that is not a valid scenario: the message is the command line's
    `FILE:LINE:COLUMN: field PATH: message`, a line a problem."""

class SimulationError(RuntimeError):
    """A run that failed as it went (a `RuntimeError`): the world could not be built, a
    calibration could not be used, a frame or its truth could not be written, a team's robots
    and their software do not match. Its subclasses say which part failed."""

class RobotSoftwareError(SimulationError):
    """The robot's software failed (a `SimulationError`): the built-in stack could not be built
    or failed on a cycle (a vision stage on a frame, a controller), a robot commanded an
    actuator it does not have, or one robot of a team failed (the message names it)."""

class RenderError(SimulationError):
    """The renderer could not open or render (a `SimulationError`): no GPU adapter for
    `renderer="gpu"`, a GPU device error, or a frame that cannot be made."""

class RunFinishedError(SimulationError):
    """A run that is over was stepped again (a `SimulationError`): time up or the goal reached;
    `reset()` it to run again."""

@final
class Scenario:
    """A scenario, checked as `omniloop check` checks it."""

    @staticmethod
    def load(path: _Path) -> Scenario:
        """Reads, parses and validates a scenario file; raises `ScenarioError` with every
        problem as `FILE:LINE:COLUMN: field PATH: message`."""

    @staticmethod
    def from_toml(text: str, name: str = "scenario") -> Scenario:
        """Parses and validates scenario text (messages name it `<string>`); `name` is its name
        when the text gives none (default `scenario`)."""

    @staticmethod
    def bundled(name: str) -> Scenario:
        """A scenario file built into omniloop (`omniloop::BUNDLED_SCENARIOS`: `"blackout_stage1"`),
        its text as `scenarios/NAME.toml` holds it; raises `ValueError` naming the others."""

    def with_values(self, values: dict[str, Any]) -> Scenario:
        """A new scenario with each dotted key (`"robot.max_speed_mm_s"`,
        `"robot.sensors[0].noise_sigma"`, `"seed"`) set to its value, validated as
        `omniloop sweep --set` validates; raises `ScenarioError` naming the key."""

    def to_toml(self) -> str:
        """The scenario's TOML text (with the values set)."""

    @property
    def name(self) -> str:
        """Its name (the file stem unless it names itself)."""

    @property
    def path(self) -> Path | None:
        """The file it came from (`None` for text)."""

    @property
    def seed(self) -> int:
        """Its seed."""

    @property
    def duration_s(self) -> float:
        """Longest simulated time, s (`run.duration_s`)."""

    @property
    def control_period_s(self) -> float:
        """One control cycle, s (`run.control_period_s`)."""

    @property
    def max_cycles(self) -> int:
        """Most control cycles a run lasts."""

    @property
    def robot(self) -> RobotInfo:
        """What the robot knows of itself: `name`, `start` (x_mm, y_mm, theta_rad), `radius_mm`,
        `max_speed_mm_s`, `accel_limit_mm_s2`, `angular_accel_limit_rad_s2`, `differential`
        (`None`, or `track_mm` and `max_turn_rate_rad_s`), `sensors` (name, width_px,
        height_px, kind, pan unit), and `goal` (`None`, or `x_mm`, `y_mm`, `tolerance_mm`,
        `waypoints_mm`); of a team, its first robot."""

    @property
    def robots(self) -> dict[str, RobotInfo]:
        """Every robot as `robot` describes it, by name, in the scenario's order (one entry for
        a one-robot scenario)."""

    def camera_model(self, sensor: str | None = None, robot: str | None = None) -> dict[str, Any]:
        """Camera `sensor` of `robot` (defaults: the first of each) as a standard camera model,
        a dict: `image_size_px`, `intrinsics` (a pinhole camera's; for a mirror, Mei's unified
        model fitted to its traced rays, as `omniloop calibrate --format opencv-omnidir`
        writes it), `model_frame_in_body` (`rotation` whose columns are the model frame's axes
        in the body frame, `translation_mm`), `pan_unit`."""

    @property
    def is_team(self) -> bool:
        """Whether the scenario has a team (`[[robots]]`)."""

@final
class RunResult:
    """What `omniloop.run` gives: the summary and the trajectory, and where the files went."""

    @property
    def summary(self) -> dict[str, Any]:
        """`summary.json` as a dict."""

    @property
    def trajectory(self) -> _Columns | Any:
        """`trajectory.csv` as a dict of NumPy columns named as its header (NaN where empty); a
        team's: a dict of these by robot name."""

    @property
    def out(self) -> Path | None:
        """The folder the run's files were written to, if any."""

@final
class Odometry:
    """What the wheel encoders measured over the last period, with the scenario's errors."""

    @property
    def vx_mm_s(self) -> float:
        """Body-frame velocity, x (forward), mm/s."""

    @property
    def vy_mm_s(self) -> float:
        """Body-frame velocity, y (left), mm/s."""

    @property
    def omega_rad_s(self) -> float:
        """Rotation rate, rad/s (counter-clockwise positive)."""

    @property
    def dt_s(self) -> float:
        """The period it covers, s (0 before the first step)."""

@final
class Observation:
    """What the robot's sensors give at the start of a control cycle."""

    @property
    def t_s(self) -> float:
        """Time of the cycle, s."""

    @property
    def cycle(self) -> int:
        """Control cycles run before it."""

    @property
    def frames(self) -> dict[str, npt.NDArray[np.uint8]]:
        """Sensor name -> `H x W x 3` `uint8` image."""

    @property
    def odometry(self) -> Odometry:
        """The last odometry reading."""

    @property
    def odometry_pose(self) -> tuple[float, float, float]:
        """Where dead reckoning of the odometry puts the robot, from the start it is told:
        `(x_mm, y_mm, theta_rad)` in the world frame."""

    @property
    def actuators(self) -> dict[str, float]:
        """Camera name -> pan angle, rad, for cameras on pan units."""

    @property
    def ball_in_dribbler(self) -> bool | None:
        """The dribbler's light barrier: whether it sees the ball (`None` without a kicker)."""

    @property
    def done(self) -> bool:
        """Whether the run is over (time up, or the goal reached where the run stops there)."""

    @property
    def estimates(self) -> dict[str, Any] | None:
        """With `robot="builtin"`: what the robot believed after the last cycle (its
        `estimates.jsonl` record without the truth); `None` otherwise."""

@final
class FreeSpaceDetector:
    """The free-space stage of one robot's vision camera, fed frame by frame."""

    def detect(self, frame: npt.NDArray[np.uint8]) -> FreeSpace:
        """The free space of `frame` (`H x W x 3` `uint8`, a frame of `camera` taken now), as the
        built-in robot's stage gives it: a dict of `direction_rad` (each direction's centre
        angle in the robot frame), `free_mm` (distance from the sensor axis to the first
        obstacle cell, or to the template's edge where free throughout), `clear_mm` (surely
        free), `front_mm` (farthest the obstacle's face can be), NumPy arrays; `range_mm` and
        `inner_mm` (the template's outer and inner edges on the floor); `axis_mm` (the sensor
        axis in the robot frame, the origin of the distances). Raises `RobotSoftwareError` when
        the stage fails on the frame (one smaller than the camera's image)."""

    @property
    def camera(self) -> str:
        """The camera whose frames it reads."""

@final
class Simulation:
    """A scenario run stepped from Python."""

    def __new__(
        cls,
        scenario: Scenario,
        seed: int | None = None,
        renderer: str = "cpu",
        robot: str | Mapping[str, str] | None = None,
        frames: bool = False,
        truth: bool = False,
    ) -> Self:
        """A run of `scenario` with `seed` (default: the scenario's), the `renderer` (`"cpu"`,
        `"gpu"` or `"auto"`) and `robot`: `"python"` (you step it with commands),
        `"builtin"` (the scenario's own robot software decides) or `"ssl"` (a team's AI over the
        SSL simulation protocol, on the ports of the scenario's `[ssl]`; `ssl_ports()`); for a
        team, one of these for every robot or a dict naming each robot's (`{"blue1": "python",
        "blue2": "builtin"}`); `frames=True` renders (and calibrates) vision's camera even where
        the built-in software reads no frame, to watch it or run a detector on it; `truth=True`
        traces the truth beside each frame (`truth_frames()`), the simulator's side only."""

    def ssl_ports(self) -> dict[str, str] | None:
        """With `robot="ssl"`: where the protocol's ports are (`control`, `blue`, `yellow`, and
        where `vision` and `referee` go), as `"host:port"`; `None` otherwise."""

    def reset(self, seed: int | None = None, scenario: Scenario | None = None) -> Observation | Any:
        """Starts the run again from its start with `seed` (default: this simulation's seed) and
        returns the first observation (a team's: a dict of observations by robot name); with
        `scenario`, runs that scenario from now on (another placement of the same robots:
        their names, cameras and actuators must be this one's, `ValueError` if not)."""

    def observe(self) -> Observation | Any:
        """The observation now (what the last `reset` or `step` returned)."""

    def step(
        self,
        command: _Command | Mapping[str, _Command] | None = None,
        actuators: _Actuators | Mapping[str, _Actuators] | None = None,
        estimate: _Estimate | Mapping[str, _Estimate] | None = None,
    ) -> Observation | Any:
        """One control cycle. The one robot driven by Python takes `command`: `(vx_mm_s,
        vy_mm_s, omega_rad_s)` in the body frame (x forward, y left; a differential robot takes
        `(v_mm_s, omega_rad_s)`), `actuators` an optional list of pan commands (`{"sensor":
        NAME, "pan_rad": A}` or `{"sensor": NAME, "rate_rad_s": W}`) and, for a robot with a
        kicker, kicks (`{"kick_mm_s": S, "angle_rad": A}`: armed until the ball is at the
        dribbler; at most the kicker's limit, `ValueError` above it or below 0) and the
        dribbler's speed (`{"dribbler_rpm": R}`), and `estimate` an
        optional `(x_mm, y_mm, theta_rad)` recorded as the robot's own estimate; with
        `robot="builtin"` no command is given. A team takes each as a dict by robot name,
        holding every robot Python drives. Returns the next observation (a team's: a dict).
        Raises `RunFinishedError` once the run is over, `RobotSoftwareError` when the built-in
        software fails, `RenderError` when the renderer does."""

    def truth(self) -> Truth | Any:
        """The truth now (the simulator's side, never part of an observation): `t_s`, `x_mm`,
        `y_mm`, `theta_rad`, `vx_mm_s`, `vy_mm_s` (world frame), `omega_rad_s`, `contacts` so
        far, `reached_goal`, `targets_reached` (with waypoints), and with a ball `ball` (`x_mm`,
        `y_mm`, `z_mm`, `vx_mm_s`, `vy_mm_s`, `vz_mm_s`) and `ball_in_dribbler`; a team's: a dict
        of these by robot name."""

    def place_ball(
        self, x_mm: float, y_mm: float, vx_mm_s: float = 0.0, vy_mm_s: float = 0.0
    ) -> None:
        """Puts the ball at `(x_mm, y_mm)` on the floor, going at `(vx_mm_s, vy_mm_s)` (an
        experimenter placing or rolling it; a dribbler holding it lets go). Raises `ValueError`
        without a ball, off the floor or with a number not finite."""

    def truth_frames(self, robot: str | None = None) -> dict[str, TruthFrame]:
        """The truth beside each frame `robot`'s software got in the last cycle (default: the
        first robot), by camera name (the simulator's side, never part of an observation):
        `depth_mm` (`float32` `H x W`: how far the light travelled to the camera, mirror
        included; inf for the sky, NaN where the pixel sees no mirror), `floor_mm` (`float32`:
        the floor point's distance from the robot's centre where the pixel shows the floor, NaN
        elsewhere), `labels` (`uint16`: what the pixel shows) and `legend` (the labels' entries
        as `legend.json` holds them). Raises `ValueError` unless made with `truth=True`."""

    def record(self) -> dict[str, Any] | None:
        """The last cycle's `estimates.jsonl` record (truth beside belief) as a dict; `None`
        before the first step (a team's: a dict of these by robot name)."""

    def summary(self) -> dict[str, Any]:
        """The run's `summary.json` so far, as a dict."""

    def trajectory(self) -> _Columns | Any:
        """The trajectory so far: a dict of NumPy columns named as `trajectory.csv`'s header (a
        team's: a dict of these by robot name)."""

    def write(self, dir: _Path) -> None:
        """Writes what `omniloop run` writes for the run so far (`summary.json`,
        `trajectory.csv`, `estimates.jsonl`, `topview.png`, the experiment's files; a team's
        records under `robots/NAME/`) into `dir`."""

    def topview(self, width: int = 640) -> npt.NDArray[np.uint8]:
        """A top view of the moment (world, paths so far, start and goal; every robot of a team)
        as an `H x W x 3` `uint8` array `width` pixels wide."""

    @property
    def scenario(self) -> Scenario:
        """The scenario being run."""

    @property
    def seed(self) -> int:
        """The seed of the run now."""

    @property
    def cycle(self) -> int:
        """Control cycles run so far."""

    @property
    def done(self) -> bool:
        """Whether the run is over."""

    def free_space_detector(self, robot: str | None = None) -> FreeSpaceDetector:
        """The free-space stage of `robot`'s vision camera (default: the first robot), built as
        the built-in robot builds it (its calibration, its `[vision.freespace]` settings), to
        run on frames from `observe()` or `step()`; raises `ValueError` when its vision camera
        is not a mirror that sees the floor."""

    @property
    def robots(self) -> list[str]:
        """The robots' names, in the scenario's order (`["robot"]` for a one-robot scenario
        that names none)."""

    @property
    def python_robots(self) -> list[str]:
        """The robots Python drives, by name."""

    @property
    def sensors(self) -> list[str] | Any:
        """The cameras, in the scenario's order (a team's: a dict of these by robot name)."""

@final
class VectorSimulation:
    """N runs of one scenario, stepped together."""

    def __new__(
        cls,
        scenario: Scenario,
        num_envs: int,
        seed: int | None = None,
        renderer: str = "cpu",
        robot: str = "python",
        truth: bool = False,
    ) -> Self:
        """`num_envs` runs of `scenario`, run `i` with seed `seed + i` (default: the scenario's
        seed), on `renderer`, with `robot` `"python"` or `"builtin"`; `truth=True` traces the
        truth beside each frame (see `Simulation`)."""

    def __len__(self) -> int:
        """How many runs."""

    def reset(
        self, index: int, seed: int | None = None, scenario: Scenario | None = None
    ) -> Observation:
        """Starts run `index` again with `seed` (default: its seed) and returns its first
        observation; with `scenario`, from that scenario instead (another placement of the
        same robot: its robots, cameras and actuators must be this one's, `ValueError` if
        not)."""

    def observe(self) -> list[Observation]:
        """Every run's observation now."""

    def step(
        self,
        commands: Sequence[_Command] | npt.NDArray[Any] | None = None,
        active: Sequence[bool] | npt.NDArray[np.bool_] | None = None,
        actuators: Sequence[_Actuators | None] | None = None,
    ) -> list[Observation]:
        """One control cycle of every run whose `active` flag is true (default: all), in
        parallel: `commands` holds a command a run (a sequence or an `N x 3` / `N x 2` array;
        `None` with `robot="builtin"`); `actuators` optionally an entry a run, `None` or a list
        as `Simulation.step` takes it (pan commands; with a kicker, `{"kick_mm_s": S,
        "angle_rad": A}` and `{"dribbler_rpm": R}`). A finished run that is active raises
        `RunFinishedError`; a command a run cannot take, `ValueError`, before any run steps.
        Returns every run's observation."""

    def truth(self) -> list[Truth]:
        """Every run's truth now (see `Simulation.truth`)."""

    def truth_frames(self) -> list[dict[str, TruthFrame]]:
        """Every run's truth beside the frames its software got in the last cycle (see
        `Simulation.truth_frames`); raises `ValueError` unless made with `truth=True`."""

    @property
    def seeds(self) -> list[int]:
        """Each run's seed."""

    @property
    def done(self) -> list[bool]:
        """Whether each run is over."""

    @property
    def scenario(self) -> Scenario:
        """The scenario being run."""

@final
class SweepPlan:
    """A checked sweep and its folder: what `sweep_plan` gives and the sweep's steps take."""

    @property
    def out(self) -> Path:
        """The sweep's folder."""

    @property
    def lines(self) -> list[str]:
        """The lines of `plan.jsonl`, the header first."""

    def open(self, resume: bool) -> list[int]:
        """Opens the sweep's journal (emptied unless `resume`): the indices of the jobs still to
        run."""

    def run_local(
        self,
        jobs: int = 0,
        renderer: str = "cpu",
        keep_runs: bool = False,
        done: Callable[[str], object] | None = None,
    ) -> None:
        """Runs the jobs the journal lacks on the Rust pool (`jobs` at a time, 0: one a core), as
        `omniloop sweep` does, each one's record appended to the journal and handed to
        `done(record_json)` as it ends. Ctrl-C stops taking jobs (the finished are kept)."""

    def report(self, plot: str = "success_rate", header: str = "") -> str:
        """Writes `sweep.csv`, `sweep.md` (after `header`) and `sweep.png` (`plot`'s metric) from
        the journal; the rows as JSON (the columns of `sweep.csv`)."""

def run(
    scenario: Scenario,
    seed: int | None = None,
    renderer: str = "cpu",
    out: _Path | None = None,
    progress: Callable[[int, int], object] | None = None,
) -> RunResult:
    """Runs `scenario` with the built-in robot as `omniloop run` does (its experiment's
    procedure, its metrics), with `seed` (default: the scenario's) on `renderer`; `out` also
    writes the run's files there; `progress(cycle, total)` is called as the run goes (at most
    a hundred times)."""

def default_scenario() -> str:
    """The commented default scenario, every key with its default (`omniloop run
    --print-default`)."""

def write_dataset(
    scenario: Scenario,
    out: _Path,
    samples: int = 100,
    poses: str = "random",
    sensor: str | None = None,
    renderer: str = "cpu",
    seed: int | None = None,
) -> dict[str, Any]:
    """Writes `samples` frames of `scenario`'s camera (`sensor`, default: the one vision uses,
    else the robot's first) with their truth into the folder `out`, as `omniloop dataset`
    does: poses `"random"` (over the floor, clear of everything) or `"along-run"` (the
    scenario's own run), with `seed` (default: the scenario's) on `renderer`. Returns
    `dataset.json`'s content as a dict."""

def read_png_levels(path: _Path) -> npt.NDArray[np.uint16]:
    """Reads a depth or label PNG as it is stored: an `H x W` `uint16` array of its grey levels
    or palette indices (label numbers, not colours). Raises `OSError` when the file cannot be
    read, `ValueError` when it is not such a PNG."""

def read_png_rgb(path: _Path) -> npt.NDArray[np.uint8]:
    """Reads an image file as an `H x W x 3` `uint8` RGB array. Raises `OSError` when the file
    cannot be read, `ValueError` when it is not an image."""

def sweep_plan(
    scenario: _Path,
    sets: dict[str, Any],
    seeds: str = "1",
    out: _Path | None = None,
) -> SweepPlan:
    """Plans the sweep of `scenario` over `sets` x `seeds` into `out` (default
    `runs/<name>_sweep`), checking every job first and writing `plan.jsonl`. Raises
    `ScenarioError` with every problem."""

def run_planned_job(
    header: str,
    job: str,
    keep: _Path | None = None,
    renderer: str = "cpu",
    threads: int = 1,
) -> str:
    """Runs one planned job, given the plan's header line and the job's line (as a Ray task gets
    them), on `threads` threads; its outputs into `keep` when given. Its record, one JSON line
    for the sweep's journal: a run that fails is recorded with its error, not raised."""
