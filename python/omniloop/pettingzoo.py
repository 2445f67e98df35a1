"""A team scenario as a PettingZoo parallel environment (``pip install "omniloop[pettingzoo]"``).

Each robot of a ``[[robots]]`` scenario that Python drives is an agent, named as the robot::

    from omniloop.pettingzoo import parallel_env

    env = parallel_env("scenarios/swarm_swap.toml")
    observations, infos = env.reset(seed=1)
    while env.agents:
        actions = {a: env.action_space(a).sample() for a in env.agents}
        observations, rewards, terminations, truncations, infos = env.step(actions)

Every agent sees, acts and is rewarded as the Gymnasium environment's one robot
(``omniloop.gym``): its observation is a ``Dict`` of its own camera images (by sensor name),
``"odometry"`` (``float32[3]``, its wheel odometry) and ``"goal"`` (``float32[2]``: its goal
in its body frame, where its own dead reckoning puts it; absent without a goal); its action a
``Box`` of body-frame velocities within its limits (with a kicker also ``kick_mm_s`` and
``dribbler_rpm``, and ``"ball_in_dribbler"`` in its observation, as ``omniloop.gym`` has them);
its reward its progress toward its goal
over the step in metres, minus ``contact_penalty`` for each new contact of its (a wall, a
cube, a pillar or another robot). Without a goal, in a scenario with a ball (a ball task), its
progress toward the ball in metres and 1.0 each time its dribbler's light barrier starts to see
the ball, less the contact penalty: every robot goes for the same ball, so the first to hold it
earns the bonus. The other robots are what its cameras show: no agent sees
another's state or the truth. ``infos[agent]`` holds its truth (for scoring, never in an
observation).

An agent whose robot reached its goal (on the truth) is terminated and leaves ``agents``; its
robot stands still from then on, an obstacle for the others. When the run's time is up, the
agents left are truncated. ``panorama={}`` (or its settings: ``{"width_px": 128, ...}``) gives
every agent's mirror cameras as their panoramas (``omniloop.panorama``), as
``omniloop.gym.PanoramaObservation`` does. ``builtin=["r5", ...]`` runs those robots on the scenario's own
software (they are no agents): five built-in robots and one policy share one floor.

Seeds: ``reset(seed=s)`` runs with seed ``s`` (the images' and odometry's noise of every
robot drawn from it); ``reset()`` without one runs the scenario's seed the first time and the
previous episode's seed plus one after.
"""

from __future__ import annotations

import functools
from typing import Any, Optional, Sequence, cast

import numpy as np

try:
    from gymnasium import spaces
    from pettingzoo import ParallelEnv
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError(
        'omniloop.pettingzoo needs PettingZoo (>= 1.24) and Gymnasium: pip install "omniloop[pettingzoo]"'
    ) from e

from . import Observation, Scenario, Simulation
from .gym import ScenarioLike, _episode_seed, _scenario, _Task
from .types import Truth

__all__ = ["OmniloopParallelEnv", "parallel_env"]


# PettingZoo has no types: its ParallelEnv is `Any` to mypy.
class OmniloopParallelEnv(ParallelEnv):  # type: ignore[misc]
    """A team scenario's robots as the agents of a PettingZoo ``ParallelEnv`` (see the module's
    documentation)."""

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "name": "omniloop_team_v0", "is_parallelizable": True}

    def __init__(
        self,
        scenario: ScenarioLike,
        renderer: str = "cpu",
        render_mode: Optional[str] = None,
        contact_penalty: float = 1.0,
        max_omega_rad_s: Optional[float] = None,
        builtin: Sequence[str] = (),
        render_width_px: int = 640,
        panorama: Optional[dict[str, Any]] = None,
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode={render_mode!r}: expected None or 'rgb_array'")
        self.scenario: Scenario = _scenario(scenario)
        robots = self.scenario.robots
        unknown = [b for b in builtin if b not in robots]
        if unknown:
            raise ValueError(
                f"builtin={list(builtin)!r}: scenario {self.scenario.name!r} has no robot "
                f"{unknown[0]!r} (its robots: {', '.join(robots)})"
            )
        self.possible_agents: list[str] = [n for n in robots if n not in builtin]
        if not self.possible_agents:
            raise ValueError("builtin= names every robot: no agent would be left to drive")
        self._tasks = {
            n: _Task(robots[n], contact_penalty, max_omega_rad_s) for n in self.possible_agents
        }
        if panorama is not None:
            for n, task in self._tasks.items():
                task.use_panorama(self.scenario, n, dict(panorama))
        drivers = {n: ("builtin" if n in builtin else "python") for n in robots}
        self.render_mode = render_mode
        self.render_width_px = render_width_px
        self.metadata = {
            **self.metadata,
            "render_fps": round(1.0 / self.scenario.control_period_s),
        }
        self.sim = Simulation(self.scenario, renderer=renderer, robot=drivers)
        self.agents: list[str] = []
        self._episode_seed: Optional[int] = None
        self._truth: dict[str, Truth] = {}
        self._still: dict[str, np.ndarray] = {}

    @functools.lru_cache(maxsize=None)
    def observation_space(self, agent: str) -> spaces.Space[Any]:
        return self._task(agent).observation_space

    @functools.lru_cache(maxsize=None)
    def action_space(self, agent: str) -> spaces.Space[Any]:
        return self._task(agent).action_space

    def _task(self, agent: str) -> _Task:
        try:
            return self._tasks[agent]
        except KeyError:
            raise ValueError(
                f"no agent {agent!r} (the agents: {', '.join(self.possible_agents)})"
            ) from None

    def reset(
        self, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None
    ) -> tuple[dict[str, dict[str, np.ndarray]], dict[str, dict[str, Any]]]:
        episode = _episode_seed(seed, self._episode_seed, self.scenario.seed)
        self._episode_seed = episode
        # A team's: by robot name.
        obs = cast("dict[str, Observation]", self.sim.reset(seed=episode))
        self._truth = cast("dict[str, Truth]", self.sim.truth())
        self.agents = list(self.possible_agents)
        self._still = {a: np.zeros(self._tasks[a].action_space.shape) for a in self.possible_agents}
        observations = {a: self._tasks[a].observation(obs[a]) for a in self.agents}
        return observations, {a: dict(self._truth[a]) for a in self.agents}

    def step(self, actions: dict[str, Any]) -> tuple[
        dict[str, dict[str, np.ndarray]],
        dict[str, float],
        dict[str, bool],
        dict[str, bool],
        dict[str, dict[str, Any]],
    ]:
        if self._episode_seed is None:
            raise RuntimeError("call reset() before step()")
        if not self.agents:
            raise RuntimeError("every agent is done: call reset() to run again")
        stray = [a for a in actions if a not in self.agents]
        if stray:
            raise ValueError(
                f"an action for {stray[0]!r}, which is not an agent now (the agents: "
                f"{', '.join(self.agents)})"
            )
        missing = [a for a in self.agents if a not in actions]
        if missing:
            raise ValueError(f"no action for agent {missing[0]!r}")
        split = {
            a: self._tasks[a].split(
                self._tasks[a].command(actions[a]) if a in actions else self._still[a]
            )
            for a in self.possible_agents
        }
        commands = {a: c for a, (c, _) in split.items()}
        kicks = {a: k for a, (_, k) in split.items() if k is not None}
        obs = cast("dict[str, Observation]", self.sim.step(commands, actuators=kicks or None))
        truth = cast("dict[str, Truth]", self.sim.truth())
        done = self.sim.done
        observations, rewards, terminations, truncations, infos = {}, {}, {}, {}, {}
        for a in self.agents:
            task = self._tasks[a]
            observations[a] = task.observation(obs[a])
            rewards[a] = float(task.reward(self._truth[a], truth[a]))
            terminations[a] = bool(truth[a]["reached_goal"])
            truncations[a] = bool(done and not terminations[a])
            infos[a] = dict(truth[a])
        self._truth = truth
        self.agents = [a for a in self.agents if not (terminations[a] or truncations[a])]
        return observations, rewards, terminations, truncations, infos

    def render(self) -> Optional[np.ndarray]:
        if self.render_mode == "rgb_array":
            return self.sim.topview(self.render_width_px)
        return None

    def close(self) -> None:
        pass


def parallel_env(scenario: ScenarioLike, **kwargs: Any) -> OmniloopParallelEnv:
    """The PettingZoo parallel environment of a team scenario (see ``OmniloopParallelEnv``)."""
    return OmniloopParallelEnv(scenario, **kwargs)
