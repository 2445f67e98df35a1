"""The vision-blackout challenge's first stage as a Gymnasium task: find the ball with the
robot's own mirror camera, drive to it and take it on the dribbler (``omniloop/BlackoutGrab-v0``,
registered by ``import omniloop.gym``)::

    import gymnasium
    import omniloop.gym

    env = gymnasium.make("omniloop/BlackoutGrab-v0")           # the panorama, 2019 placements
    obs, info = env.reset(seed=1)
    venv = omniloop.grab.make_vec(16, time_limit_s=10.0)      # 16 runs stepped in Rust

Placements (drawn from the episode's seed, so every episode is reproducible):

- ``"2019"`` (the 2019 rules' stage 1): the robot anywhere on the 4 m x 3 m field with its 1 m
  x 1 m box 300 mm inside the lines, any heading; the ball anywhere in that box, at least
  200 mm from the robot's centre (its body and the ball apart).
- ``"2021"``: robot and ball anywhere on the field 300 mm inside the lines and out of the
  defense areas, the ball at least 400 mm from the robot (``omniloop replay blackout``'s
  stage-1 trials).

The robot is ``scenarios/blackout_stage1.toml``'s (built into omniloop:
``Scenario.bundled("blackout_stage1")``): E1's hyperbolic mirror camera (256 x 220, noise sigma
4) on a 90 mm body with the league's kicker, 1.5 m/s and 2 m/s^2, wheel odometry with its
errors. The dribbler spins at its full speed throughout; the kicker is never armed. The
settings are ``GrabConfig``'s fields.

- Observation (``observation=``): ``"panorama"`` (default: the camera's panorama, ``uint8``
  ``H x W x 3``, ``omniloop.panorama.Panorama`` with ``panorama=`` its settings),
  ``"image"`` (the raw mirror image, 220 x 256 x 3), or ``"state"`` (``float32[2]``: the ball's
  true position in the body frame, m; privileged, for a baseline of what learning from pixels
  costs, never a robot's); with ``"odometry"`` (``float32[3]``: the odometry's body-frame
  velocity in m/s and turn rate in rad/s) and ``"ball_in_dribbler"`` (``float32[1]``, the
  light barrier), the robot's own sensors. ``stack=k`` (and ``stack_every=e``) gives the
  last ``k`` images or strips, ``e`` steps apart, on the channels, newest first (``H x W x
  3k``): a memory, for the ball goes into the body's blind zone (within about 350 mm of the
  robot's centre, under the mirror's own reflection) as the robot closes on it.
- Action: ``Box(-1, 1, (3,))``, the body-frame velocity as fractions of the top speed (x
  forward, y left) and of ``max_omega_rad_s`` (default 4 rad/s, counter-clockwise).
- Reward (potential-based shaping, A. Ng, D. Harada and S. Russell, ICML 1999, eq. 2, with
  gamma = 1): ``phi(s') - phi(s)`` with ``phi = -(d + 0.25 |b| / pi)``, ``d`` the true distance
  between the robot's and the ball's centres in m and ``b`` the ball's bearing from the
  robot's forward, plus 1 when the light barrier first sees the ball and -1 at a contact with
  a wall (or goal). The truth feeds the reward only.
- ``terminated`` at success (the light barrier sees the ball: touched with the dribbler) or at
  a wall contact; ``truncated`` when ``time_limit_s`` (default 60 s, the rules' minute) is up.
- ``info``: ``success``, ``time_s`` (since the start), ``wall_contact``, ``state`` (the
  ball's true body-frame position, m) and the truth: for scoring, or for a critic that
  learns values during training only (an asymmetric actor-critic), never in the observation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

import gymnasium
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from . import Observation, Scenario, Simulation, VectorSimulation
from .gym import RunSeeds
from .panorama import Panorama
from .types import Truth

ENV_ID = "omniloop/BlackoutGrab-v0"
OBSERVATIONS = ("panorama", "image", "state")
PLACEMENTS = ("2019", "2021")

#: The field's half length and width (the hardware challenge's 4 m x 3 m), the margin kept from
#: the lines and the defense areas' depth and half width, mm.
HALF_LENGTH_MM, HALF_WIDTH_MM, MARGIN_MM = 2000.0, 1500.0, 300.0
DEFENSE_DEPTH_MM, DEFENSE_HALF_WIDTH_MM = 800.0, 1000.0

def default_scenario() -> Scenario:
    """The task's scenario: ``scenarios/blackout_stage1.toml``, built into omniloop
    (``Scenario.bundled``); the task sets its run's length and each episode's placement."""
    return Scenario.bundled("blackout_stage1")


@dataclass(frozen=True)
class GrabConfig:
    """The task's settings: the keyword arguments of ``GrabEnv``, ``GrabVectorEnv``,
    ``make_vec`` and ``gymnasium.make(ENV_ID, ...)``, checked by ``GrabTask``."""

    #: ``"panorama"``, ``"image"`` or ``"state"`` (see the module's documentation).
    observation: str = "panorama"
    #: ``"2019"`` or ``"2021"``: the rules the placements follow.
    placements: str = "2019"
    #: An episode's length (the rules' minute), s.
    time_limit_s: float = 60.0
    #: The turn rate an action of 1 asks for, rad/s.
    max_omega_rad_s: float = 4.0
    #: ``omniloop.panorama.Panorama``'s settings (``width_px``, ``height_px``, ...).
    panorama: Optional[dict[str, Any]] = None
    #: Images or strips in an observation, and the steps between them.
    stack: int = 1
    stack_every: int = 1
    #: Another robot (default: ``default_scenario()``); it needs a kicker and a camera.
    scenario: Optional[Scenario] = None
    #: ``"cpu"`` (bit-reproducible) or ``"gpu"``.
    renderer: str = "cpu"

    @staticmethod
    def of(settings: dict[str, Any]) -> GrabConfig:
        """The settings from keyword arguments; raises ``ValueError`` naming an unknown one."""
        known = [f.name for f in fields(GrabConfig)]
        for key in settings:
            if key not in known:
                raise ValueError(f"{key}=: no such setting of {ENV_ID}; one of {', '.join(known)}")
        return GrabConfig(**settings)


def placement(seed: int, kind: str = "2019") -> tuple[tuple[float, float, float], tuple[float, float]]:
    """The robot's start ``(x_mm, y_mm, heading_rad)`` and the ball's ``(x_mm, y_mm)`` of
    episode ``seed`` under ``kind``'s rules (see the module's documentation)."""
    if kind not in PLACEMENTS:
        raise ValueError(f"placements={kind!r}: one of {', '.join(PLACEMENTS)}")
    rng = np.random.default_rng([int(seed), 2019 if kind == "2019" else 2021])
    heading = float(rng.uniform(-math.pi, math.pi))
    if kind == "2019":
        rx = float(rng.uniform(-1.0, 1.0)) * (HALF_LENGTH_MM - MARGIN_MM - 500.0)
        ry = float(rng.uniform(-1.0, 1.0)) * (HALF_WIDTH_MM - MARGIN_MM - 500.0)
        while True:
            bx, by = (float(v) for v in rng.uniform(-500.0, 500.0, 2))
            if math.hypot(bx, by) >= 200.0:
                return (rx, ry, heading), (rx + bx, ry + by)
    robot = _free_spot(rng)
    while True:
        ball = _free_spot(rng)
        if math.hypot(ball[0] - robot[0], ball[1] - robot[1]) >= 400.0:
            return (robot[0], robot[1], heading), ball


def _free_spot(rng: np.random.Generator) -> tuple[float, float]:
    """A point 300 mm inside the lines and out of the defense areas (with the margin)."""
    while True:
        x = float(rng.uniform(-1.0, 1.0)) * (HALF_LENGTH_MM - MARGIN_MM)
        y = float(rng.uniform(-1.0, 1.0)) * (HALF_WIDTH_MM - MARGIN_MM)
        in_area = (
            abs(x) > HALF_LENGTH_MM - DEFENSE_DEPTH_MM - MARGIN_MM
            and abs(y) < DEFENSE_HALF_WIDTH_MM + MARGIN_MM
        )
        if not in_area:
            return x, y


class FrameHistory:
    """Each run's last frames, given as ``stack`` of them ``every`` steps apart, stacked on the
    channels newest first (``H x W x 3 stack``): a memory of what went by (the ball goes out
    of the mirror's view into the body's blind zone as the robot closes on it)."""

    def __init__(self, stack: int, every: int) -> None:
        if not (isinstance(stack, int) and 1 <= stack <= 16):
            raise ValueError(f"stack={stack!r}: an int from 1 to 16")
        if not (isinstance(every, int) and 1 <= every <= 16):
            raise ValueError(f"stack_every={every!r}: an int from 1 to 16")
        self.stack, self.every = stack, every
        self.depth = (stack - 1) * every + 1
        self._ring: Optional[npt.NDArray[np.uint8]] = None
        self._pos = 0

    def update(self, frames: npt.NDArray[np.uint8], fresh: npt.NDArray[np.bool_]) -> npt.NDArray[np.uint8]:
        """Adds each run's frame (``N x H x W x C``; ``fresh`` runs start their history
        over, filled with it) and returns the stacks."""
        if self.stack == 1:
            return frames
        if self._ring is None or self._ring.shape[0] != frames.shape[0]:
            self._ring = np.repeat(frames[:, None], self.depth, axis=1)
            fresh = np.ones(frames.shape[0], dtype=bool)
        self._pos = (self._pos - 1) % self.depth
        self._ring[:, self._pos] = frames
        self._ring[fresh] = frames[fresh][:, None]
        picked = [self._ring[:, (self._pos + j * self.every) % self.depth] for j in range(self.stack)]
        return np.concatenate(picked, axis=-1)


class GrabTask:
    """What the single and the vector environment share: the placements' scenarios, the
    spaces, observation, reward and ends."""

    def __init__(self, config: GrabConfig = GrabConfig()) -> None:
        self.config = c = config
        observation, placements, stack = c.observation, c.placements, c.stack
        time_limit_s, max_omega_rad_s = float(c.time_limit_s), float(c.max_omega_rad_s)
        if observation not in OBSERVATIONS:
            raise ValueError(f"observation={observation!r}: one of {', '.join(OBSERVATIONS)}")
        if placements not in PLACEMENTS:
            raise ValueError(f"placements={placements!r}: one of {', '.join(PLACEMENTS)}")
        if not (math.isfinite(time_limit_s) and 0.0 < time_limit_s <= 600.0):
            raise ValueError(f"time_limit_s={time_limit_s}: above 0 and at most 600")
        if not (math.isfinite(max_omega_rad_s) and max_omega_rad_s > 0.0):
            raise ValueError(f"max_omega_rad_s={max_omega_rad_s}: a finite number > 0")
        base = default_scenario() if c.scenario is None else c.scenario
        robot = base.robot
        if robot["kicker"] is None or not robot["sensors"]:
            raise ValueError(f"scenario {base.name!r}: the task needs a robot with a kicker and a camera")
        self.base = base.with_values({"run.duration_s": float(time_limit_s)})
        self.camera = robot["sensors"][0]["name"]
        self.max_speed = float(robot["max_speed_mm_s"])
        self.max_omega = float(max_omega_rad_s)
        self.full_rpm = float(robot["kicker"]["full_pull_rpm"])
        self.panorama = (
            Panorama.of(self.base, self.camera, **(c.panorama or {}))
            if observation == "panorama" else None
        )
        self.stack = 1 if observation == "state" else stack
        FrameHistory(stack, c.stack_every)  # checks them
        self.observation_space = spaces.Dict(self._parts(robot))
        self.action_space = spaces.Box(-1.0, 1.0, (3,), dtype=np.float32)

    def _parts(self, robot: Any) -> dict[str, spaces.Space[Any]]:
        s = robot["sensors"][0]
        h, w, _ = self.panorama.shape if self.panorama is not None else (s["height_px"], s["width_px"], 3)
        if self.config.observation != "state":
            first: spaces.Space[Any] = spaces.Box(0, 255, (h, w, 3 * self.stack), dtype=np.uint8)
        else:
            first = spaces.Box(-np.inf, np.inf, (2,), dtype=np.float32)
        return {
            self.config.observation: first,
            "odometry": spaces.Box(-np.inf, np.inf, (3,), dtype=np.float32),
            "ball_in_dribbler": spaces.Box(0.0, 1.0, (1,), dtype=np.float32),
        }

    def scenario(self, seed: int) -> Scenario:
        """Episode ``seed``'s scenario: the base with the placement drawn from the seed."""
        (rx, ry, heading), (bx, by) = placement(seed, self.config.placements)
        return self.base.with_values({
            "robot.start.x_mm": rx,
            "robot.start.y_mm": ry,
            "robot.start.heading_deg": math.degrees(heading),
            "world.ball.center_mm": [bx, by],
        })

    def command(self, action: Any) -> tuple[npt.NDArray[np.float64], list[Any]]:
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        if a.shape != (3,):
            raise ValueError(f"action of shape {a.shape}: the action space is {self.action_space}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"action {a} is not finite")
        a = np.clip(a, -1.0, 1.0)
        motion = np.array([a[0] * self.max_speed, a[1] * self.max_speed, a[2] * self.max_omega])
        return motion, [{"kick_mm_s": 0.0}, {"dribbler_rpm": self.full_rpm}]

    def batch(
        self, obs: list[Observation], truths: list[Truth], history: FrameHistory,
        fresh: npt.NDArray[np.bool_],
    ) -> dict[str, npt.NDArray[Any]]:
        """The observations of a batch of runs (``fresh``: those whose episode starts)."""
        each = [self.observation(o, t) for o, t in zip(obs, truths)]
        out = {k: np.stack([e[k] for e in each]) for k in self.observation_space.keys()}
        kind = self.config.observation
        if kind != "state":
            frames = out[kind] if self.panorama is None else self.panorama(out[kind])
            out[kind] = history.update(frames, fresh)
        return out

    def observation(self, obs: Observation, truth: Truth) -> dict[str, npt.NDArray[Any]]:
        o = obs.odometry
        out: dict[str, npt.NDArray[Any]] = {
            "odometry": np.array(
                [o.vx_mm_s / 1000.0, o.vy_mm_s / 1000.0, o.omega_rad_s], dtype=np.float32
            ),
            "ball_in_dribbler": np.array([1.0 if obs.ball_in_dribbler else 0.0], dtype=np.float32),
        }
        frame = obs.frames[self.camera]
        if self.config.observation != "state":  # the env unwarps and stacks its batch at once
            out[self.config.observation] = frame
        else:
            out["state"] = ball_state(truth)
        return out

    @staticmethod
    def potential(truth: Truth) -> float:
        d, b = ball_polar(truth)
        return -(d + 0.25 * abs(b) / math.pi)

    def outcome(self, before: Truth, after: Truth, start_t_s: float) -> tuple[float, bool, dict[str, Any]]:
        """The step's reward, whether it ends the episode, and its ``info`` keys."""
        success = bool(after.get("ball_in_dribbler", False))
        wall = after["contacts"] > before["contacts"]
        reward = self.potential(after) - self.potential(before)
        reward += (1.0 if success else 0.0) - (1.0 if wall else 0.0)
        info = {"success": success, "wall_contact": bool(wall), "time_s": after["t_s"] - start_t_s}
        return reward, success or bool(wall), info


def ball_state(truth: Truth) -> npt.NDArray[np.float32]:
    """The ball's true position in the robot's body frame, m (x forward, y left)."""
    d, b = ball_polar(truth)
    return np.array([d * math.cos(b), d * math.sin(b)], dtype=np.float32)


def ball_polar(truth: Truth) -> tuple[float, float]:
    """The ball's true distance (m, centre to centre) and bearing (rad, from the robot's
    forward, counter-clockwise) from the robot."""
    b = truth["ball"]
    dx, dy = b["x_mm"] - truth["x_mm"], b["y_mm"] - truth["y_mm"]
    bearing = math.atan2(dy, dx) - truth["theta_rad"]
    return math.hypot(dx, dy) / 1000.0, math.atan2(math.sin(bearing), math.cos(bearing))


class GrabEnv(gymnasium.Env):
    """The task as one Gymnasium environment (see the module's documentation)."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 25}

    def __init__(self, render_mode: Optional[str] = None, **settings: Any) -> None:
        """``settings``: ``GrabConfig``'s fields."""
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode={render_mode!r}: expected None or 'rgb_array'")
        self.task = GrabTask(GrabConfig.of(settings))
        self._history = FrameHistory(self.task.stack, self.task.config.stack_every)
        self.observation_space = self.task.observation_space
        self.action_space = self.task.action_space
        self.render_mode = render_mode
        self.sim = Simulation(self.task.base, renderer=self.task.config.renderer)
        self._seed: Optional[int] = None
        self._truth: Truth = self.sim.truth()

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None
    ) -> tuple[dict[str, npt.NDArray[Any]], dict[str, Any]]:
        super().reset(seed=seed)
        self._seed = int(seed) if seed is not None else (1 if self._seed is None else self._seed + 1)
        obs = self.sim.reset(seed=self._seed, scenario=self.task.scenario(self._seed))
        self._truth = self.sim.truth()
        info = {
            "success": False, "wall_contact": False, "time_s": 0.0, **self._truth,
            "state": ball_state(self._truth),
        }
        return self._one(obs, self._truth, True), info

    def step(
        self, action: Any
    ) -> tuple[dict[str, npt.NDArray[Any]], float, bool, bool, dict[str, Any]]:
        if self._seed is None:
            raise RuntimeError("call reset() before step()")
        motion, actuators = self.task.command(action)
        obs = self.sim.step(motion, actuators=actuators)
        truth = self.sim.truth()
        reward, terminated, info = self.task.outcome(self._truth, truth, 0.0)
        self._truth = truth
        truncated = bool(obs.done and not terminated)
        info = {**truth, **info, "state": ball_state(truth)}
        return self._one(obs, truth, False), reward, terminated, truncated, info

    def _one(self, obs: Observation, truth: Truth, fresh: bool) -> dict[str, npt.NDArray[Any]]:
        out = self.task.batch([obs], [truth], self._history, np.array([fresh]))
        return {k: v[0] for k, v in out.items()}

    def render(self) -> Optional[npt.NDArray[np.uint8]]:
        return self.sim.topview(640) if self.render_mode == "rgb_array" else None


class GrabVectorEnv(VectorEnv):
    """``num_envs`` runs of the task stepped together in Rust (in parallel on the cores), with
    Gymnasium's next-step autoreset. Run ``i`` starts with seed ``seed + i``; after an episode
    its seed goes up by ``num_envs``, so the runs never share a placement."""

    metadata = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int, **settings: Any) -> None:
        """``settings``: ``GrabConfig``'s fields."""
        self.task = GrabTask(GrabConfig.of(settings))
        self._history = FrameHistory(self.task.stack, self.task.config.stack_every)
        self.num_envs = int(num_envs)
        self.single_observation_space = self.task.observation_space
        self.single_action_space = self.task.action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.render_mode = None
        self.vec = VectorSimulation(self.task.base, self.num_envs, renderer=self.task.config.renderer)
        self._seeds = RunSeeds(self.num_envs, 1)
        self._truths: list[Truth] = self.vec.truth()
        self._autoreset = np.zeros(self.num_envs, dtype=bool)

    def _start(self, i: int, seed: int) -> Observation:
        return self.vec.reset(i, seed, scenario=self.task.scenario(seed))

    def reset(
        self,
        *,
        seed: Optional[Union[int, Sequence[int]]] = None,
        options: Optional[dict[str, Any]] = None,
    ) -> tuple[dict[str, npt.NDArray[Any]], dict[str, Any]]:
        seeds = self._seeds.reset(seed)
        obs = [self._start(i, s) for i, s in enumerate(seeds)]
        self._truths = self.vec.truth()
        self._autoreset[:] = False
        fresh = np.ones(self.num_envs, dtype=bool)
        infos = {"seed": np.array(seeds), "state": self._states(self._truths)}
        return self.task.batch(obs, self._truths, self._history, fresh), infos

    def step(
        self, actions: Any
    ) -> tuple[dict[str, npt.NDArray[Any]], npt.NDArray[np.float64], npt.NDArray[np.bool_],
               npt.NDArray[np.bool_], dict[str, Any]]:
        self._seeds.check_started()
        acts = np.asarray(actions, dtype=np.float64).reshape(self.num_envs, -1)
        commands = [self.task.command(a) for a in acts]
        resetting = self._autoreset.copy()
        for k in np.flatnonzero(resetting):
            self._start(int(k), self._seeds.next(int(k)))
        motions = np.stack([m for m, _ in commands])
        obs = self.vec.step(motions, active=[not r for r in resetting], actuators=[a for _, a in commands])
        truths = self.vec.truth()
        n = self.num_envs
        rewards, terminated = np.zeros(n), np.zeros(n, dtype=bool)
        truncated = np.zeros(n, dtype=bool)
        success, time_s = np.zeros(n, dtype=bool), np.zeros(n)
        for i in range(n):
            if resetting[i]:
                continue
            rewards[i], terminated[i], info = self.task.outcome(self._truths[i], truths[i], 0.0)
            success[i], time_s[i] = info["success"], info["time_s"]
            truncated[i] = obs[i].done and not terminated[i]
        self._truths = truths
        self._autoreset = terminated | truncated
        infos = {
            "success": success, "time_s": time_s, "seed": np.array(self._seeds.check_started()),
            "state": self._states(truths),
        }
        batch = self.task.batch(obs, truths, self._history, resetting)
        return batch, rewards, terminated, truncated, infos

    @staticmethod
    def _states(truths: list[Truth]) -> npt.NDArray[np.float32]:
        return np.stack([ball_state(t) for t in truths])


def make_vec(num_envs: int, **settings: Any) -> GrabVectorEnv:
    """``num_envs`` runs of the task (see ``GrabVectorEnv``; ``settings``: ``GrabConfig``'s fields)."""
    return GrabVectorEnv(num_envs, **settings)


__all__ = [
    "ENV_ID", "FrameHistory", "GrabConfig", "GrabEnv", "GrabTask", "GrabVectorEnv", "ball_polar", "ball_state",
    "default_scenario",
    "make_vec", "placement",
]
