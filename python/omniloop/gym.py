"""Gymnasium environments of omniloop scenarios (``pip install "omniloop[gym]"``).

Importing this module registers ``omniloop/Scenario-v0`` (and ``omniloop/BlackoutGrab-v0``, the
vision-blackout challenge's first stage as a learning task: ``omniloop.grab``)::

    import gymnasium
    import omniloop.gym

    env = gymnasium.make("omniloop/Scenario-v0", scenario="scenarios/smoke.toml")
    obs, info = env.reset(seed=1)

- Observation: a ``Dict`` space with one ``uint8`` ``H x W x 3`` image per camera (keyed by
  sensor name), ``"odometry"`` (``float32[3]``: the wheel odometry's body-frame velocity x, y
  in mm/s and rotation rate in rad/s, with the scenario's errors) and ``"goal"``
  (``float32[2]``: the goal in the body frame, mm, where the robot's own dead reckoning puts
  it; absent when the scenario has no goal).
- Action: a ``Box`` of body-frame velocities within the scenario's limits:
  ``(vx_mm_s, vy_mm_s, omega_rad_s)`` with ``|v| <= robot.max_speed_mm_s`` per axis and
  ``|omega| <= max_omega_rad_s`` (default pi rad/s), or ``(v_mm_s, omega_rad_s)`` for a
  differential robot (its turn rate limit from ``[robot.differential]``). A robot with a kicker
  (``[robot.kicker]``) takes two more: ``kick_mm_s`` (0 to its kicker's limit: above 0 arms a
  flat kick that fires when the ball is at the dribbler, 0 disarms) and ``dribbler_rpm`` (0 to
  its full pull's speed), and its observation has ``"ball_in_dribbler"`` (``float32[1]``: the
  light barrier, 1 when it sees the ball); the vector environment's runs take them alike.
  Actions outside are clipped to the box; the world then scales a velocity over the top speed
  down to it by its norm (a diagonal at the box's corner runs at the top speed, not 1.41 times it).
- Reward: progress toward the goal over the step in metres (the true distance before minus
  after), minus ``contact_penalty`` (default 1.0) for each new contact with a wall, cube,
  pillar or robot. A ball task (a scenario with a ball and no goal: the vision-blackout
  challenge's first stage) rewards the robot's progress toward the ball in metres (the true
  distance between their centres before minus after) and 1.0 each
  time its dribbler's light barrier starts to see the ball, less the contact penalty; without
  a goal or a ball, the contact penalty alone.
- ``terminated`` when the goal is reached (on the truth, within its tolerance);
  ``truncated`` when ``run.duration_s`` is up.
- ``info``: the truth (``t_s``, ``x_mm``, ``y_mm``, ``theta_rad``, ``contacts``,
  ``reached_goal``, ...): the simulator's side, for scoring; never in the observation.
- ``truth_frames=True``: ``info["truth_frames"]`` also holds the truth beside each frame the
  robot's software got, after ``reset`` and every step (``Simulation.truth_frames()``: per
  camera name ``"depth_mm"`` and ``"floor_mm"`` as ``float32`` ``H x W``, ``"labels"`` as
  ``uint16`` ``H x W``, and ``"legend"``), for perception's losses and scores; never in the
  observation. The vector environment gives it as an object array of these dicts, one a run.
- ``render_mode="rgb_array"``: ``render()`` returns a top view of the moment.
- ``PanoramaObservation(env)`` (``VectorPanoramaObservation`` for the vector environment)
  gives each mirror camera's image as its panorama strip (``omniloop.panorama``): azimuth
  across, elevation down, the robot's heading a circular shift of the columns.

Seeds: ``reset(seed=s)`` runs with seed ``s``; ``reset()`` without one runs the scenario's
seed the first time and the previous episode's seed plus one after, so that every episode is
reproducible. The vector environment gives run ``i`` seed ``s + i`` and, after an episode,
its previous seed plus ``num_envs``.
"""

from __future__ import annotations

import math
import os
from typing import Any, Optional, Sequence, Union

from .types import RobotInfo, Truth

import numpy as np

try:
    import gymnasium
    from gymnasium import spaces
    from gymnasium.vector import AutoresetMode, VectorEnv
    from gymnasium.vector.utils import batch_space
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError(
        "omniloop.gym needs Gymnasium (>= 1.1): pip install \"omniloop[gym]\""
    ) from e

from . import Observation, Scenario, Simulation, VectorSimulation

ENV_ID = "omniloop/Scenario-v0"

ScenarioLike = Union[Scenario, str, "os.PathLike[str]"]


def _scenario(scenario: ScenarioLike) -> Scenario:
    if isinstance(scenario, Scenario):
        return scenario
    if isinstance(scenario, (str, os.PathLike)):
        return Scenario.load(scenario)
    raise TypeError(
        f"scenario must be an omniloop.Scenario or a path, not {type(scenario).__name__}"
    )


def _one_robot(scenario: Scenario) -> Scenario:
    if scenario.is_team:
        raise ValueError(
            f"scenario {scenario.name!r} has a team ([[robots]]): its robots are agents of "
            "omniloop.pettingzoo.parallel_env, not one Gymnasium environment"
        )
    return scenario


def _episode_seed(seed: Optional[int], previous: Optional[int], first: int) -> int:
    """The seed of the next episode: the one asked for, else the scenario's the first time and
    the previous episode's plus one after."""
    if seed is not None:
        return int(seed)
    return first if previous is None else previous + 1


class _Task:
    """What the single and the vector environment (and each agent of the PettingZoo
    environment) share: spaces, observation, reward, for one robot (``Scenario.robot``)."""

    def __init__(
        self,
        robot: RobotInfo,
        contact_penalty: float,
        max_omega_rad_s: Optional[float],
    ) -> None:
        if not (math.isfinite(contact_penalty) and contact_penalty >= 0.0):
            raise ValueError(f"contact_penalty={contact_penalty}: a finite number >= 0")
        self.sensors = [(s["name"], s["height_px"], s["width_px"]) for s in robot["sensors"]]
        goal = robot["goal"]
        self.goal = None if goal is None else (goal["x_mm"], goal["y_mm"])
        self.contact_penalty = float(contact_penalty)
        self.hold_bonus = 1.0
        vmax = robot["max_speed_mm_s"]
        diff = robot["differential"]
        if diff is not None:
            wmax = diff["max_turn_rate_rad_s"] if max_omega_rad_s is None else max_omega_rad_s
            high = np.array([vmax, wmax], dtype=np.float32)
        else:
            wmax = math.pi if max_omega_rad_s is None else max_omega_rad_s
            high = np.array([vmax, vmax, wmax], dtype=np.float32)
        if not (math.isfinite(wmax) and wmax > 0.0):
            raise ValueError(f"max_omega_rad_s={max_omega_rad_s}: a finite number > 0")
        low = -high
        self.kicker = robot["kicker"]
        #: How many of the action's numbers drive the wheels (the rest: kick, dribbler).
        self.motion = len(high)
        if self.kicker is not None:
            more = [self.kicker["max_kick_mm_s"], self.kicker["full_pull_rpm"]]
            high = np.concatenate([high, np.array(more, dtype=np.float32)])
            low = np.concatenate([low, np.zeros(2, dtype=np.float32)])
        self.action_space = spaces.Box(low, high, dtype=np.float32)
        parts: dict[str, spaces.Space[Any]] = {
            name: spaces.Box(0, 255, (h, w, 3), dtype=np.uint8) for name, h, w in self.sensors
        }
        if {"odometry", "goal", "ball_in_dribbler"} & set(parts):
            raise ValueError(
                "a camera may not be called `odometry`, `goal` or `ball_in_dribbler` in a Gym env"
            )
        parts["odometry"] = spaces.Box(-np.inf, np.inf, (3,), dtype=np.float32)
        if self.kicker is not None:
            parts["ball_in_dribbler"] = spaces.Box(0.0, 1.0, (1,), dtype=np.float32)
        if self.goal is not None:
            parts["goal"] = spaces.Box(-np.inf, np.inf, (2,), dtype=np.float32)
        self.observation_space = spaces.Dict(parts)
        #: Cameras given as their panorama, by name (``use_panorama``).
        self.panoramas: dict[str, Any] = {}

    def use_panorama(self, scenario: Scenario, robot: Optional[str], settings: dict[str, Any]) -> None:
        """Gives each mirror camera's image as its panorama (``omniloop.panorama``)."""
        from .panorama import Panorama

        info = scenario.robots[robot] if robot is not None else scenario.robot
        for s in info["sensors"]:
            if s["kind"] != "pinhole":
                pano = Panorama.of(scenario, s["name"], robot, **settings)
                self.panoramas[s["name"]] = pano
                self.observation_space[s["name"]] = spaces.Box(0, 255, pano.shape, dtype=np.uint8)

    def observation(self, obs: Observation) -> dict[str, np.ndarray]:
        out: dict[str, np.ndarray] = {name: obs.frames[name] for name, _, _ in self.sensors}
        for name, pano in self.panoramas.items():
            out[name] = pano(out[name])
        o = obs.odometry
        out["odometry"] = np.array([o.vx_mm_s, o.vy_mm_s, o.omega_rad_s], dtype=np.float32)
        if self.kicker is not None:
            seen = 1.0 if obs.ball_in_dribbler else 0.0
            out["ball_in_dribbler"] = np.array([seen], dtype=np.float32)
        if self.goal is not None:
            x, y, theta = obs.odometry_pose
            dx, dy = self.goal[0] - x, self.goal[1] - y
            c, s = math.cos(theta), math.sin(theta)
            out["goal"] = np.array([c * dx + s * dy, -s * dx + c * dy], dtype=np.float32)
        return out

    def distance_m(self, truth: Truth) -> float:
        if self.goal is None:
            return 0.0
        return math.hypot(self.goal[0] - truth["x_mm"], self.goal[1] - truth["y_mm"]) / 1000.0

    def reward(self, before: Truth, after: Truth) -> float:
        progress = self.distance_m(before) - self.distance_m(after)
        if self.goal is None and "ball" in after and "ball" in before:
            progress = self.to_ball_m(before) - self.to_ball_m(after)
            took = after.get("ball_in_dribbler", False) and not before.get("ball_in_dribbler", False)
            progress += self.hold_bonus if took else 0.0
        return progress - self.contact_penalty * (after["contacts"] - before["contacts"])

    @staticmethod
    def to_ball_m(truth: Truth) -> float:
        """The true distance from the robot's centre to the ball's, m."""
        b = truth["ball"]
        return math.hypot(b["x_mm"] - truth["x_mm"], b["y_mm"] - truth["y_mm"]) / 1000.0

    def command(self, action: Any) -> np.ndarray:
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        if a.shape != self.action_space.shape:
            raise ValueError(
                f"action of shape {a.shape}: the action space is {self.action_space}"
            )
        if not np.all(np.isfinite(a)):
            raise ValueError(f"action {a} is not finite")
        return np.clip(a, self.action_space.low, self.action_space.high)

    def split(self, a: np.ndarray) -> tuple[np.ndarray, Optional[list[Any]]]:
        """A clipped action as the wheels' command and, with a kicker, the kick and dribbler
        commands of ``Simulation.step``."""
        if self.kicker is None:
            return a, None
        kick, rpm = float(a[self.motion]), float(a[self.motion + 1])
        return a[: self.motion], [{"kick_mm_s": kick}, {"dribbler_rpm": rpm}]


class OmniloopEnv(gymnasium.Env):
    """One omniloop scenario as a Gymnasium environment (see the module's documentation)."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 25}

    def __init__(
        self,
        scenario: ScenarioLike,
        renderer: str = "cpu",
        render_mode: Optional[str] = None,
        contact_penalty: float = 1.0,
        max_omega_rad_s: Optional[float] = None,
        render_width_px: int = 640,
        truth_frames: bool = False,
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode={render_mode!r}: expected None or 'rgb_array'")
        self.scenario = _one_robot(_scenario(scenario))
        self._task = _Task(self.scenario.robot, contact_penalty, max_omega_rad_s)
        self.observation_space = self._task.observation_space
        self.action_space = self._task.action_space
        self.render_mode = render_mode
        self.render_width_px = render_width_px
        self.metadata = {**self.metadata, "render_fps": round(1.0 / self.scenario.control_period_s)}
        self.truth_frames = bool(truth_frames)
        self.sim = Simulation(self.scenario, renderer=renderer, truth=self.truth_frames)
        self._episode_seed: Optional[int] = None
        self._truth = self.sim.truth()

    def _info(self, truth: Truth) -> dict[str, Any]:
        info: dict[str, Any] = dict(truth)
        if self.truth_frames:
            info["truth_frames"] = self.sim.truth_frames()
        return info

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        super().reset(seed=seed)
        episode = _episode_seed(seed, self._episode_seed, self.scenario.seed)
        self._episode_seed = episode
        obs = self.sim.reset(seed=episode)
        self._truth = self.sim.truth()
        return self._task.observation(obs), self._info(self._truth)

    def step(
        self, action: Any
    ) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        if self._episode_seed is None:
            raise RuntimeError("call reset() before step()")
        motion, actuators = self._task.split(self._task.command(action))
        obs = self.sim.step(motion, actuators=actuators)
        truth = self.sim.truth()
        reward = self._task.reward(self._truth, truth)
        self._truth = truth
        terminated = bool(truth["reached_goal"])
        truncated = bool(obs.done and not terminated)
        return self._task.observation(obs), float(reward), terminated, truncated, self._info(truth)

    def render(self) -> Optional[np.ndarray]:
        if self.render_mode == "rgb_array":
            return self.sim.topview(self.render_width_px)
        return None


class RunSeeds:
    """The episode seeds of a vector environment's runs. ``reset(s)`` gives run ``i`` seed
    ``s + i`` (or each run its own from a sequence of ``num_envs``); ``reset(None)`` gives
    run ``i`` ``first + i`` the first time and its previous seed plus ``num_envs`` after;
    ``next(i)``, at the end of run ``i``'s episode, moves its seed up by ``num_envs``. Each
    run keeps to its own residue modulo ``num_envs``: no two episodes share a seed."""

    def __init__(self, num_envs: int, first: int) -> None:
        self.num_envs, self.first = int(num_envs), int(first)
        self.seeds: Optional[list[int]] = None

    def reset(self, seed: Optional[Union[int, Sequence[int]]]) -> list[int]:
        n = self.num_envs
        if seed is None:
            seeds = [self.first + i for i in range(n)] if self.seeds is None else [s + n for s in self.seeds]
        elif isinstance(seed, int):
            seeds = [seed + i for i in range(n)]
        else:
            seeds = [int(s) for s in seed]
            if len(seeds) != n:
                raise ValueError(f"{len(seeds)} seeds for {n} runs")
        self.seeds = seeds
        return list(seeds)

    def check_started(self) -> list[int]:
        """The runs' seeds; raises ``RuntimeError`` before the first ``reset``."""
        if self.seeds is None:
            raise RuntimeError("call reset() before step()")
        return self.seeds

    def next(self, run: int) -> int:
        """Run ``run``'s next episode seed (its episode ended)."""
        seeds = self.check_started()
        seeds[run] += self.num_envs
        return seeds[run]


class OmniloopVectorEnv(VectorEnv):
    """N runs of one scenario stepped together in Rust, in parallel on the cores (and in
    shared GPU batches on a GPU renderer); Gymnasium's next-step autoreset: the step after an
    episode ends resets that run and returns its first observation with reward 0."""

    metadata = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(
        self,
        scenario: ScenarioLike,
        num_envs: int,
        renderer: str = "cpu",
        contact_penalty: float = 1.0,
        max_omega_rad_s: Optional[float] = None,
        truth_frames: bool = False,
    ) -> None:
        self.scenario = _one_robot(_scenario(scenario))
        self._task = _Task(self.scenario.robot, contact_penalty, max_omega_rad_s)
        self.num_envs = int(num_envs)
        self.single_observation_space = self._task.observation_space
        self.single_action_space = self._task.action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.render_mode = None
        self.truth_frames = bool(truth_frames)
        self.vec = VectorSimulation(
            self.scenario, self.num_envs, renderer=renderer, truth=self.truth_frames
        )
        self._seeds = RunSeeds(self.num_envs, self.scenario.seed)
        self._truths = self.vec.truth()
        self._autoreset = np.zeros(self.num_envs, dtype=bool)

    def reset(
        self,
        *,
        seed: Optional[Union[int, Sequence[int]]] = None,
        options: Optional[dict[str, Any]] = None,
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        super().reset(seed=None if seed is None or not isinstance(seed, int) else seed)
        seeds = self._seeds.reset(seed)
        obs = [self.vec.reset(i, s) for i, s in enumerate(seeds)]
        self._truths = self.vec.truth()
        self._autoreset[:] = False
        return self._batch(obs), self._infos(self._truths)

    def step(
        self, actions: Any
    ) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        self._seeds.check_started()
        actions = np.asarray(actions, dtype=np.float64)
        n = self.num_envs
        if actions.shape[0] != n:
            raise ValueError(f"{actions.shape[0]} actions for {n} runs")
        split = [self._task.split(self._task.command(a)) for a in actions]
        motions = np.stack([m for m, _ in split])
        kicks = None if self._task.kicker is None else [k for _, k in split]
        resetting = self._autoreset.copy()
        for k in np.flatnonzero(resetting):
            self.vec.reset(int(k), self._seeds.next(int(k)))
        obs = self.vec.step(motions, active=[not r for r in resetting], actuators=kicks)
        truths = self.vec.truth()
        rewards = np.zeros(n, dtype=np.float64)
        terminated = np.zeros(n, dtype=bool)
        truncated = np.zeros(n, dtype=bool)
        for i in range(n):
            if resetting[i]:
                continue
            rewards[i] = self._task.reward(self._truths[i], truths[i])
            terminated[i] = truths[i]["reached_goal"]
            truncated[i] = obs[i].done and not terminated[i]
        self._truths = truths
        self._autoreset = terminated | truncated
        return self._batch(obs), rewards, terminated, truncated, self._infos(truths)

    def _batch(self, obs: list[Observation]) -> dict[str, np.ndarray]:
        each = [self._task.observation(o) for o in obs]
        return {k: np.stack([e[k] for e in each]) for k in self._task.observation_space.keys()}

    def _infos(self, truths: list[Truth]) -> dict[str, Any]:
        infos: dict[str, Any] = {}
        rows: list[dict[str, Any]] = [dict(t) for t in truths]
        for key in rows[0]:
            values = [t[key] for t in rows]
            if any(v is None for v in values):
                continue
            infos[key] = np.array(values)
            infos["_" + key] = np.ones(self.num_envs, dtype=bool)
        if self.truth_frames:
            frames = np.empty(self.num_envs, dtype=object)
            frames[:] = self.vec.truth_frames()
            infos["truth_frames"] = frames
            infos["_truth_frames"] = np.ones(self.num_envs, dtype=bool)
        return infos


def _panorama_spaces(
    space: spaces.Dict, scenario: Scenario, sensors: Optional[Sequence[str]], settings: dict[str, Any]
) -> tuple[dict[str, Any], spaces.Dict]:
    """The panoramas of ``sensors`` (default: every mirror camera of the observation) and the
    observation space with their strips in place of their images."""
    from .panorama import Panorama

    mirrors = [s["name"] for s in scenario.robot["sensors"] if s["kind"] != "pinhole"]
    names = list(mirrors if sensors is None else sensors)
    unknown = [n for n in names if n not in space.spaces]
    if unknown or not names:
        raise ValueError(
            f"sensors={sensors!r}: cameras of the observation to unwarp (its mirror cameras: "
            f"{', '.join(mirrors) or 'none'})"
        )
    panos = {n: Panorama.of(scenario, n, **settings) for n in names}
    parts = dict(space.spaces)
    for n, p in panos.items():
        parts[n] = spaces.Box(0, 255, p.shape, dtype=np.uint8)
    return panos, spaces.Dict(parts)


class PanoramaObservation(gymnasium.ObservationWrapper):
    """An ``omniloop/Scenario-v0`` environment whose mirror cameras' images (or ``sensors``')
    are given as their panoramas (``omniloop.panorama.Panorama``; ``settings`` its keyword
    arguments: ``width_px``, ``height_px``, ``elevation_deg`` or ``floor_mm``, ``samples``)."""

    def __init__(self, env: gymnasium.Env, sensors: Optional[Sequence[str]] = None,
                 **settings: Any) -> None:
        super().__init__(env)
        scenario: Scenario = env.get_wrapper_attr("scenario")
        self.panoramas, self.observation_space = _panorama_spaces(
            env.observation_space, scenario, sensors, settings  # type: ignore[arg-type]
        )

    def observation(self, observation: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        return {k: (self.panoramas[k](v) if k in self.panoramas else v) for k, v in observation.items()}


class VectorPanoramaObservation(gymnasium.vector.VectorObservationWrapper):
    """``PanoramaObservation`` for the vector environment: each batch of images is unwarped at
    once."""

    def __init__(self, env: VectorEnv, sensors: Optional[Sequence[str]] = None, **settings: Any) -> None:
        super().__init__(env)
        scenario: Scenario = getattr(env.unwrapped, "scenario")
        self.panoramas, self.single_observation_space = _panorama_spaces(
            env.single_observation_space, scenario, sensors, settings  # type: ignore[arg-type]
        )
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)

    def observations(self, observations: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        return {k: (self.panoramas[k](v) if k in self.panoramas else v) for k, v in observations.items()}


def make_vec(
    scenario: ScenarioLike, num_envs: int, renderer: str = "cpu", **kwargs: Any
) -> OmniloopVectorEnv:
    """A vector environment of ``num_envs`` runs of ``scenario`` (see ``OmniloopVectorEnv``)."""
    return OmniloopVectorEnv(scenario, num_envs, renderer=renderer, **kwargs)


gymnasium.register(
    id=ENV_ID,
    entry_point="omniloop.gym:OmniloopEnv",
    vector_entry_point="omniloop.gym:OmniloopVectorEnv",
)
# The vision-blackout challenge's first stage as a learning task (``omniloop.grab``).
gymnasium.register(
    id="omniloop/BlackoutGrab-v0",
    entry_point="omniloop.grab:GrabEnv",
    vector_entry_point="omniloop.grab:GrabVectorEnv",
)

__all__ = [
    "ENV_ID", "OmniloopEnv", "OmniloopVectorEnv", "PanoramaObservation", "RunSeeds",
    "VectorPanoramaObservation", "make_vec",
]
