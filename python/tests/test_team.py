"""A team from Python: a command and an observation per robot name, built-in and Python robots
on one floor, bad input refused with the robot named, and the PettingZoo environment."""

import math

import numpy as np
import pytest

import omniloop
from conftest import SCENARIOS, goal_in_body, to_goal

PAIR = """
name = "pair"
[run]
duration_s = 3.0
[[world.walls]]
from_mm = [-1500.0, -700.0]
to_mm = [1500.0, -700.0]
[[world.walls]]
from_mm = [-1500.0, 700.0]
to_mm = [1500.0, 700.0]
[robot]
accel_limit_mm_s2 = 1000.0
[[robot.sensors]]
name = "omni"
width_px = 128
height_px = 110
noise_sigma = 4.0
[robot.sensors.hyperbolic]
a_mm = 12.129
b_mm = 15.650
c_mm = 19.8
focal_px = 239.685
focus_height_mm = 205.08
rim_radius_mm = 30.0
[control]
kind = "velocity_aware"
[control.planner]
kind = "none"
[control.avoidance.traffic]
rule = "reciprocal"
[[robots]]
name = "east"
start = { x_mm = -900.0, y_mm = 0.0 }
goal = { x_mm = 900.0, y_mm = 0.0 }
marking_rgb = [25, 60, 220]
[[robots]]
name = "west"
start = { x_mm = 900.0, y_mm = 0.0, heading_deg = 180.0 }
goal = { x_mm = -900.0, y_mm = 0.0 }
marking_rgb = [235, 200, 20]
"""


@pytest.fixture(scope="module")
def pair() -> omniloop.Scenario:
    return omniloop.Scenario.from_toml(PAIR)


def test_a_scenario_tells_its_robots(pair):
    assert pair.is_team
    assert list(pair.robots) == ["east", "west"]
    assert pair.robots["west"]["start"][0] == 900.0
    assert pair.robots["west"]["goal"]["x_mm"] == -900.0
    assert pair.robot["name"] == "east", "a team's robot is its first"
    smoke = omniloop.Scenario.load(SCENARIOS / "smoke.toml")
    assert not smoke.is_team and list(smoke.robots) == ["robot"]


def test_a_team_steps_with_a_command_per_robot_and_sees_per_robot(pair):
    sim = omniloop.Simulation(pair, seed=3)
    assert sim.robots == ["east", "west"] and sim.python_robots == ["east", "west"]
    obs = sim.reset()
    assert set(obs) == {"east", "west"}
    assert obs["east"].frames["omni"].shape == (110, 128, 3)
    goals = {n: (r["goal"]["x_mm"], r["goal"]["y_mm"]) for n, r in pair.robots.items()}
    for _ in range(10):
        obs = sim.step({n: to_goal(goal_in_body(obs[n], goals[n])) for n in sim.robots})
    truth = sim.truth()
    assert truth["east"]["x_mm"] > -900.0 and truth["west"]["x_mm"] < 900.0
    # Each robot's odometry is its own: they drive opposite ways.
    assert obs["east"].odometry_pose[0] > -900.0 and obs["west"].odometry_pose[0] < 900.0
    assert set(sim.trajectory()) == {"east", "west"}
    assert len(sim.trajectory()["west"]["x_mm"]) == 10
    summary = sim.summary()
    assert summary["team"]["robots"] == 2
    assert [r["name"] for r in summary["robots"]] == ["east", "west"]


def test_the_same_seed_gives_the_same_team_run(pair):
    def run(seed):
        sim = omniloop.Simulation(pair, seed=seed, robot="builtin")
        sim.reset()
        while not sim.done:
            sim.step()
        return sim.trajectory(), sim.summary()

    (a, sa), (b, sb) = run(5), run(5)
    for name in ("east", "west"):
        for column in ("x_mm", "y_mm", "vx_mm_s"):
            assert np.array_equal(a[name][column], b[name][column])
    assert sa["team"] == sb["team"]


def test_built_in_and_python_robots_share_one_floor(pair):
    sim = omniloop.Simulation(pair, robot={"east": "python", "west": "builtin"})
    assert sim.python_robots == ["east"]
    obs = sim.reset()
    assert obs["west"].estimates is None, "no cycle yet"
    for _ in range(8):
        obs = sim.step({"east": (0.0, 0.0, 0.0)})
    assert obs["west"].estimates is not None, "the built-in robot records its beliefs"
    assert obs["east"].estimates is None
    truth = sim.truth()
    assert truth["east"]["x_mm"] == pytest.approx(-900.0, abs=0.5), "Python held it still"
    assert truth["west"]["x_mm"] < 900.0 - 10.0, "the built-in robot drove"


@pytest.mark.parametrize(
    "robot, message",
    [
        ({"east": "python"}, 'robot "west" has no software'),
        ({"east": "python", "west": "python", "north": "builtin"}, "no robot of that name"),
        ({"east": "python", "west": "remote"}, "expected \"python\""),
    ],
)
def test_a_robot_without_software_or_a_stranger_is_refused(pair, robot, message):
    with pytest.raises(ValueError, match=message):
        omniloop.Simulation(pair, robot=robot)


def test_bad_team_commands_are_refused_naming_the_robot(pair):
    sim = omniloop.Simulation(pair, robot={"east": "python", "west": "builtin"})
    sim.reset()
    with pytest.raises(ValueError, match='no command for robot "east"'):
        sim.step({})
    with pytest.raises(ValueError, match='no robot "north"'):
        sim.step({"east": (0.0, 0.0, 0.0), "north": (0.0, 0.0, 0.0)})
    with pytest.raises(ValueError, match='"west" runs the built-in software'):
        sim.step({"east": (0.0, 0.0, 0.0), "west": (0.0, 0.0, 0.0)})
    with pytest.raises(ValueError, match="takes command as a dict"):
        sim.step((0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match='robot "east": command has 2 numbers'):
        sim.step({"east": (0.0, 0.0)})
    with pytest.raises(ValueError, match='robot "east"'):
        sim.step({"east": (math.nan, 0.0, 0.0)})
    assert sim.cycle == 0, "a refused step runs nothing"


def test_a_team_is_no_gymnasium_environment(pair):
    pytest.importorskip("gymnasium")
    import omniloop.gym

    with pytest.raises(ValueError, match="omniloop.pettingzoo"):
        omniloop.gym.OmniloopEnv(pair)
    with pytest.raises(ValueError, match="Simulation or omniloop.pettingzoo"):
        omniloop.VectorSimulation(pair, 2)


def test_the_pettingzoo_environment_passes_pettingzoos_own_tests(pair):
    pytest.importorskip("pettingzoo")
    from pettingzoo.test import parallel_api_test, parallel_seed_test

    from omniloop.pettingzoo import parallel_env

    env = parallel_env(pair)
    assert env.possible_agents == ["east", "west"]
    parallel_api_test(env, num_cycles=40)
    parallel_seed_test(lambda: parallel_env(pair), num_cycles=20)


def test_pettingzoo_agents_get_the_gym_observation_and_are_rewarded_for_progress(pair):
    pytest.importorskip("pettingzoo")
    from omniloop.pettingzoo import parallel_env

    env = parallel_env(pair, builtin=["west"])
    assert env.possible_agents == ["east"]
    obs, infos = env.reset(seed=2)
    assert set(obs["east"]) == {"omni", "odometry", "goal"}
    assert obs["east"]["goal"][0] == pytest.approx(1800.0, abs=1.0)
    assert env.observation_space("east").contains(obs["east"])
    total = 0.0
    for _ in range(15):
        obs, rewards, terms, truncs, infos = env.step({"east": np.array([400.0, 0.0, 0.0])})
        total += rewards["east"]
    # Driving toward its goal is rewarded by the metres gained.
    assert total == pytest.approx((infos["east"]["x_mm"] + 900.0) / 1000.0, abs=1e-6)
    with pytest.raises(ValueError, match="not an agent"):
        env.step({"east": np.zeros(3), "west": np.zeros(3)})
    with pytest.raises(ValueError, match="has no robot 'north'"):
        parallel_env(pair, builtin=["north"])


def test_a_whole_team_run_from_python_writes_what_the_command_line_writes(pair, tmp_path):
    result = omniloop.run(pair, out=tmp_path / "pair")
    assert set(result.trajectory) == {"east", "west"}
    assert result.summary["team"]["robots"] == 2
    assert (tmp_path / "pair" / "robots" / "west" / "estimates.jsonl").is_file()
    header = (tmp_path / "pair" / "trajectory.csv").read_text().splitlines()[0]
    assert header.startswith("robot,t_s,")
