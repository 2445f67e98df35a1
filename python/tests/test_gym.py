"""The Gymnasium environments: the checker, a goal reached on the observation alone,
determinism, and a vector of runs that each give the trajectory they give alone."""

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")
from gymnasium.utils.env_checker import check_env  # noqa: E402

import omniloop  # noqa: E402
import omniloop.gym  # noqa: E402
from conftest import SCENARIOS, to_goal  # noqa: E402


def test_make_registers_the_env_and_check_env_passes(corner):
    env = gymnasium.make(
        omniloop.gym.ENV_ID, scenario=SCENARIOS / "corner55_velocity_aware.toml",
        render_mode="rgb_array",
    )
    check_env(env.unwrapped)
    obs, info = env.reset(seed=1)
    assert set(obs) == {"omni", "odometry", "goal"}
    assert obs["omni"].shape == (220, 256, 3) and obs["omni"].dtype == np.uint8
    assert obs["odometry"].dtype == np.float32 and obs["goal"].dtype == np.float32
    assert info["reached_goal"] is False and "x_mm" in info
    frame = env.render()
    assert frame.ndim == 3 and frame.shape[2] == 3 and frame.dtype == np.uint8
    env.close()


def test_check_env_passes_without_cameras(smoke):
    env = omniloop.gym.OmniloopEnv(smoke)
    check_env(env, skip_render_check=True)
    assert set(env.observation_space.spaces) == {"odometry", "goal"}


def test_a_python_controller_reaches_the_smoke_goal_on_the_goal_observation(smoke):
    env = gymnasium.make(omniloop.gym.ENV_ID, scenario=smoke)
    obs, info = env.reset(seed=7)
    total, steps = 0.0, 0
    while True:
        obs, reward, terminated, truncated, info = env.step(np.array(to_goal(obs["goal"])))
        total += reward
        steps += 1
        if terminated or truncated:
            break
    assert terminated and not truncated
    assert info["reached_goal"] is True and info["contacts"] == 0
    start = np.array(smoke.robot["start"][:2])
    goal = np.array([smoke.robot["goal"]["x_mm"], smoke.robot["goal"]["y_mm"]])
    tolerance_m = smoke.robot["goal"]["tolerance_mm"] / 1000.0
    # The reward is the progress in metres: the start's distance less where it ended.
    assert total == pytest.approx(np.linalg.norm(goal - start) / 1000.0, abs=tolerance_m)
    assert steps < smoke.max_cycles


def test_contacts_cost_the_penalty(smoke):
    wall = smoke.with_values({"robot.start": {"x_mm": 1150.0, "y_mm": -600.0}})
    env = omniloop.gym.OmniloopEnv(wall, contact_penalty=5.0)
    env.reset(seed=1)
    rewards, info = [], {}
    for _ in range(60):
        _, r, terminated, truncated, info = env.step(np.array([400.0, 0.0, 0.0]))
        rewards.append(r)
    assert info["contacts"] >= 1
    assert min(rewards) < -4.0


def test_episodes_are_reproducible(corner):
    env = omniloop.gym.OmniloopEnv(corner)
    def episode(seed):
        obs, _ = env.reset(seed=seed)
        frames = [obs["omni"]]
        for _ in range(5):
            obs, *_ = env.step(np.array(to_goal(obs["goal"])))
            frames.append(obs["omni"])
        return frames
    a, b = episode(3), episode(3)
    assert all(np.array_equal(x, y) for x, y in zip(a, b))


def run_alone(scenario, seed, steps):
    env = omniloop.gym.OmniloopEnv(scenario)
    obs, info = env.reset(seed=seed)
    out = [(obs["omni"], info["x_mm"], info["y_mm"])]
    for _ in range(steps):
        obs, _, _, _, info = env.step(np.array(to_goal(obs["goal"])))
        out.append((obs["omni"], info["x_mm"], info["y_mm"]))
    return out


def test_a_vector_of_four_gives_each_run_its_trajectory_alone(corner):
    steps, n = 12, 4
    vec = omniloop.gym.make_vec(corner, num_envs=n)
    obs, info = vec.reset(seed=30)
    assert obs["omni"].shape == (n, 220, 256, 3)
    runs = [[(obs["omni"][i], info["x_mm"][i], info["y_mm"][i])] for i in range(n)]
    for _ in range(steps):
        actions = np.stack([to_goal(g) for g in obs["goal"]])
        obs, rewards, terminated, truncated, info = vec.step(actions)
        assert rewards.shape == (n,) and not terminated.any() and not truncated.any()
        for i in range(n):
            runs[i].append((obs["omni"][i], info["x_mm"][i], info["y_mm"][i]))
    for i in range(n):
        alone = run_alone(corner, 30 + i, steps)
        for k, ((f, x, y), (fa, xa, ya)) in enumerate(zip(runs[i], alone)):
            assert np.array_equal(f, fa), f"run {i}, step {k}: frames differ"
            assert (x, y) == (xa, ya), f"run {i}, step {k}: pose differs"
    vec.close()


def test_the_vector_env_resets_a_finished_run_on_the_next_step(smoke):
    short = smoke.with_values({"run.duration_s": 0.2})
    vec = omniloop.gym.make_vec(short, num_envs=2)
    obs, info = vec.reset(seed=5)
    assert list(vec.vec.seeds) == [5, 6]
    still = np.zeros((2, 3))
    for _ in range(4):
        assert not vec.step(still)[3].any()
    obs, rewards, terminated, truncated, info = vec.step(still)
    assert truncated.all(), "time is up after five cycles"
    obs, rewards, terminated, truncated, info = vec.step(still)
    assert (rewards == 0).all() and not truncated.any()
    assert (info["t_s"] == 0).all(), "each run started again"
    assert list(vec.vec.seeds) == [7, 8], "a new episode, a new seed"


def test_run_seeds_never_give_two_episodes_one_seed():
    seeds = omniloop.gym.RunSeeds(3, first=10)
    with pytest.raises(RuntimeError, match="reset"):
        seeds.next(0)
    assert seeds.reset(None) == [10, 11, 12]
    assert [seeds.next(0), seeds.next(0), seeds.next(2)] == [13, 16, 15]
    assert seeds.reset(None) == [19, 14, 18], "each run its previous seed plus 3"
    assert seeds.reset(4) == [4, 5, 6]
    with pytest.raises(ValueError, match="2 seeds for 3 runs"):
        seeds.reset([1, 2])


def test_bad_actions_raise(smoke):
    env = omniloop.gym.OmniloopEnv(smoke)
    env.reset(seed=1)
    with pytest.raises(ValueError, match="not finite"):
        env.step(np.array([np.nan, 0.0, 0.0]))
    with pytest.raises(ValueError, match="shape"):
        env.step(np.zeros(5))
    with pytest.raises(TypeError):
        omniloop.gym.OmniloopEnv(42)
