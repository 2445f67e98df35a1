"""The ball from Python: a kick through `Simulation.step`'s actuators, the light barrier in the
observation, the ball in the truth, placing it, refused kicks; the Gymnasium and PettingZoo
checks on a scenario with a ball; kicks through `VectorSimulation` and the vector
environment."""

import math

import pytest

import omniloop
from conftest import SCENARIOS


@pytest.fixture(scope="module")
def rollout() -> omniloop.Scenario:
    """A robot with a kicker, the ball at its front, an open floor; no camera."""
    return omniloop.Scenario.load(SCENARIOS / "ball_rollout.toml")


def test_a_kick_from_python_sends_the_ball_off_at_its_speed(rollout):
    sim = omniloop.Simulation(rollout)
    obs = sim.reset(seed=1)
    assert obs.ball_in_dribbler is True
    truth = sim.truth()
    assert truth["ball"]["vx_mm_s"] == 0.0 and truth["ball_in_dribbler"] is True
    obs = sim.step((0.0, 0.0, 0.0), actuators=[{"kick_mm_s": 3000.0}])
    ball = sim.truth()["ball"]
    # One 40 ms cycle after the kick: sliding at 3.9 m/s^2 from 3 m/s.
    assert ball["vx_mm_s"] == pytest.approx(3000.0 - 3900.0 * 0.04, abs=3900.0 * 0.0021)
    assert abs(ball["vy_mm_s"]) < 1e-9
    assert obs.ball_in_dribbler is False
    sim.step((0.0, 0.0, 0.0))
    assert sim.truth()["ball"]["x_mm"] > 96.5 + 100.0


def test_a_chip_flies(rollout):
    sim = omniloop.Simulation(rollout)
    sim.reset(seed=1)
    sim.step((0.0, 0.0, 0.0), actuators=[{"kick_mm_s": 4000.0, "angle_rad": math.radians(45)}])
    ball = sim.truth()["ball"]
    assert ball["z_mm"] > 21.5 + 50.0 and ball["vz_mm_s"] > 0.0


def test_refused_kicks_and_places_raise_value_error(rollout):
    sim = omniloop.Simulation(rollout)
    sim.reset(seed=1)
    with pytest.raises(ValueError, match="limit"):
        sim.step((0.0, 0.0, 0.0), actuators=[{"kick_mm_s": 7000.0}])
    with pytest.raises(ValueError, match="kick speed"):
        sim.step((0.0, 0.0, 0.0), actuators=[{"kick_mm_s": -1.0}])
    with pytest.raises(ValueError, match="dribbler_rpm"):
        sim.step((0.0, 0.0, 0.0), actuators=[{"dribbler_rpm": float("nan")}])
    with pytest.raises(ValueError, match="finite"):
        sim.place_ball(float("nan"), 0.0)
    sim.place_ball(500.0, 200.0, vx_mm_s=-100.0)
    ball = sim.truth()["ball"]
    assert (ball["x_mm"], ball["y_mm"], ball["vx_mm_s"]) == (500.0, 200.0, -100.0)


def test_a_robot_without_a_kicker_cannot_kick(smoke):
    sim = omniloop.Simulation(smoke)
    obs = sim.reset(seed=1)
    assert obs.ball_in_dribbler is None
    with pytest.raises(ValueError, match="no kicker"):
        sim.step((0.0, 0.0, 0.0), actuators=[{"kick_mm_s": 1000.0}])
    with pytest.raises(ValueError, match="no ball"):
        sim.place_ball(0.0, 0.0)


def test_gymnasium_and_pettingzoo_checks_pass_with_a_ball():
    gymnasium = pytest.importorskip("gymnasium")
    from gymnasium.utils.env_checker import check_env

    import omniloop.gym

    scenario = omniloop.Scenario.load(SCENARIOS / "ball_kick.toml")
    env = omniloop.gym.OmniloopEnv(scenario)
    check_env(env, skip_render_check=True)
    assert gymnasium is not None
    # The kicker's two numbers after the wheels', the light barrier in the observation.
    assert env.action_space.shape == (5,)
    assert list(env.action_space.high[3:]) == [6500.0, 5000.0]
    assert env.observation_space["ball_in_dribbler"].shape == (1,)
    # The vector environment's runs take the same actions and observe the same.
    vec = omniloop.gym.OmniloopVectorEnv(scenario, num_envs=2)
    assert vec.single_action_space == env.action_space
    assert vec.single_observation_space == env.observation_space
    vec.close()
    pytest.importorskip("pettingzoo")
    from pettingzoo.test import parallel_api_test

    import omniloop.pettingzoo

    teams = omniloop.Scenario.load(SCENARIOS / "ssl_teams_ball.toml")
    parallel_api_test(omniloop.pettingzoo.parallel_env(teams), num_cycles=3)


def test_a_gym_agent_kicks_with_its_action(rollout):
    import numpy as np

    pytest.importorskip("gymnasium")
    import omniloop.gym

    env = omniloop.gym.OmniloopEnv(rollout)
    obs, _ = env.reset(seed=1)
    assert obs["ball_in_dribbler"][0] == 1.0
    obs, _, _, _, info = env.step(np.array([0.0, 0.0, 0.0, 2000.0, 0.0], dtype=np.float32))
    assert info["ball"]["vx_mm_s"] > 1500.0
    assert obs["ball_in_dribbler"][0] == 0.0


def test_the_world_holds_every_robot_to_its_top_speed_by_the_norm(smoke):
    # smoke.toml's robot: 400 mm/s at most, 300 mm/s^2; a diagonal of 400 on each axis asks 566.
    sim = omniloop.Simulation(smoke)
    sim.reset(seed=1)
    for _ in range(50):  # 2 s: at full speed from 1.33 s, clear of the cubes and the walls
        sim.step((400.0, 400.0, 0.0))
    t = sim.truth()
    assert math.hypot(t["vx_mm_s"], t["vy_mm_s"]) == pytest.approx(400.0, abs=1.0)


def test_a_vector_env_kicks_and_dribbles_through_its_actions(rollout):
    """Three runs of ball_rollout.toml, the ball at each robot's dribbler: run 0 kicks at 2 m/s,
    run 1 at the limit, run 2 spins its dribbler alone. Each run's ball goes as the single
    environment's does with the same seed and action; the batched observations and sampled
    actions stay in their spaces."""
    import numpy as np

    pytest.importorskip("gymnasium")
    import omniloop.gym

    vec = omniloop.gym.make_vec(rollout, num_envs=3)
    assert vec.single_action_space.shape == (5,)
    assert vec.action_space.shape == (3, 5)
    assert vec.observation_space["ball_in_dribbler"].shape == (3, 1)
    obs, _ = vec.reset(seed=1)
    assert vec.observation_space.contains(obs)
    assert (obs["ball_in_dribbler"] == 1.0).all()
    actions = np.zeros((3, 5), dtype=np.float32)
    actions[0, 3], actions[1, 3], actions[2, 4] = 2000.0, 6500.0, 3000.0
    obs_kick, _, _, _, info = vec.step(actions)
    assert vec.observation_space.contains(obs_kick)
    assert list(obs_kick["ball_in_dribbler"][:, 0]) == [0.0, 0.0, 1.0]
    vx = [ball["vx_mm_s"] for ball in info["ball"]]
    assert vx[0] == pytest.approx(2000.0 - 3900.0 * 0.04, abs=10.0)
    assert vx[1] == pytest.approx(6500.0 - 3900.0 * 0.04, abs=10.0)
    assert vx[2] == 0.0
    # The same as one environment alone, to the bit.
    for i, action in enumerate(actions):
        env = omniloop.gym.OmniloopEnv(rollout)
        env.reset(seed=1 + i)
        assert env.step(action)[4]["ball"] == info["ball"][i]
    for _ in range(5):
        obs = vec.step(vec.action_space.sample())[0]
        assert vec.observation_space.contains(obs)
    # Gymnasium's determinism check, on the vector: the same seed and actions, the same step.
    from gymnasium.utils.env_checker import data_equivalence

    vec.reset(seed=1)
    again = vec.step(actions)
    assert data_equivalence(again[0], obs_kick) and data_equivalence(again[4], info, exact=True)
    vec.close()


def test_vector_simulation_checks_each_runs_kicker_commands(rollout, smoke):
    import numpy as np

    still = np.zeros((2, 3))
    vec = omniloop.VectorSimulation(rollout, 2, seed=1)
    with pytest.raises(ValueError, match="run 1: .*over the kicker's limit"):
        vec.step(still, actuators=[None, [{"kick_mm_s": 7000.0}]])
    with pytest.raises(ValueError, match="1 actuators for 2 runs"):
        vec.step(still, actuators=[None])
    assert vec.observe()[0].t_s == 0.0, "a refused command steps no run"
    obs = vec.step(still, actuators=[[{"dribbler_rpm": 3000.0}], [{"kick_mm_s": 1000.0}]])
    assert [o.ball_in_dribbler for o in obs] == [True, False]
    assert [t["ball"]["vx_mm_s"] > 500.0 for t in vec.truth()] == [False, True]
    no_kicker = omniloop.VectorSimulation(smoke, 2)
    with pytest.raises(ValueError, match="run 0: .*no kicker"):
        no_kicker.step(still, actuators=[[{"kick_mm_s": 1000.0}], None])
    builtin = omniloop.VectorSimulation(rollout, 2, robot="builtin")
    with pytest.raises(ValueError, match="decides its own commands"):
        builtin.step(actuators=[None, None])


def test_a_ball_task_rewards_going_for_the_ball_and_taking_it():
    """Stage 1 of the vision blackout from Gymnasium: moving toward the ball earns its progress
    in metres, the light barrier's first sight of the ball 1.0 more."""
    import numpy as np

    pytest.importorskip("gymnasium")
    import omniloop.gym

    env = omniloop.gym.OmniloopEnv(SCENARIOS / "blackout_stage1.toml", renderer="cpu")
    _, info = env.reset(seed=1)

    def to_ball(t):
        return math.hypot(t["ball"]["x_mm"] - t["x_mm"], t["ball"]["y_mm"] - t["y_mm"])

    before = to_ball(info)
    _, reward, _, _, info = env.step(np.array([0.0, 1000.0, 0.0, 0.0, 0.0], dtype=np.float32))
    assert reward == pytest.approx((before - to_ball(info)) / 1000.0, abs=1e-9)
    assert reward != 0.0
    # Rolled onto the front of the dribbler, the ball is taken: the bonus on top of the progress
    # (both from the truth before the step, as the environment keeps it).
    c, s = math.cos(info["theta_rad"]), math.sin(info["theta_rad"])
    env.sim.place_ball(info["x_mm"] + 105.0 * c, info["y_mm"] + 105.0 * s, -400.0 * c, -400.0 * s)
    before = info
    for _ in range(10):
        _, reward, _, _, info = env.step(np.array([0.0, 0.0, 0.0, 0.0, 5000.0], dtype=np.float32))
        if info["ball_in_dribbler"]:
            break
        before = info
    assert info["ball_in_dribbler"], "the rolling ball reached the dribbler"
    progress = (to_ball(before) - to_ball(info)) / 1000.0
    assert reward == pytest.approx(progress + 1.0, abs=1e-9)


def test_the_python_striker_example_grabs_the_ball():
    """python/examples/grab_ball.py plays stage 1 from the mirror image alone."""
    import subprocess
    import sys

    from conftest import ROOT

    out = subprocess.run(
        [sys.executable, "python/examples/grab_ball.py", "1"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
    ).stdout
    assert "held the ball: True" in out, out
