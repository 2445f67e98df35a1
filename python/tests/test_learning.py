"""The panorama, the grab task and the training example: learning from the mirror image."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path
from typing import Any, Optional

import numpy as np
import pytest

import gymnasium
import omniloop
import omniloop.gym
import omniloop.grab as grab
from omniloop.panorama import Panorama, yaw_augment

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def task() -> grab.GrabTask:
    return grab.GrabTask(grab.GrabConfig(time_limit_s=10.0))


def strip_at(task: grab.GrabTask, heading_deg: float, ball: tuple[float, float]) -> np.ndarray:
    """The panorama of the robot at the origin facing ``heading_deg``, the ball at ``ball``,
    without the camera's noise."""
    s = task.base.with_values({
        "robot.start.x_mm": 0.0, "robot.start.y_mm": 0.0, "robot.start.heading_deg": heading_deg,
        "world.ball.center_mm": list(ball), "robot.sensors": [{**_sensor(task), "noise_sigma": 0.0}],
    })
    frame = omniloop.Simulation(s).reset().frames["omni"]
    assert task.panorama is not None
    return task.panorama(frame)


def _sensor(task: Optional[grab.GrabTask]) -> dict[str, Any]:
    return {
        "name": "omni", "width_px": 256, "height_px": 220,
        "hyperbolic": {"a_mm": 12.129, "b_mm": 15.650, "c_mm": 19.8, "focal_px": 479.37,
                       "focus_height_mm": 205.08, "rim_radius_mm": 30.0},
    }


def ball_columns(task: grab.GrabTask, heading_deg: float, bearing_rad: float) -> tuple[np.ndarray, np.ndarray]:
    """The strip with the ball 600 mm away at ``bearing_rad`` from the robot's forward, and
    the columns where it shows: where the strip is redder than with the ball on the other
    side (an orange ball on the green floor; the goals and walls cancel out)."""
    h = math.radians(heading_deg)

    def at(bearing: float) -> np.ndarray:
        a = h + bearing
        return strip_at(task, heading_deg, (600.0 * math.cos(a), 600.0 * math.sin(a)))

    strip, other = at(bearing_rad), at(bearing_rad + math.pi)
    redder = strip[..., 0].astype(np.int32) - other[..., 0].astype(np.int32)
    return strip, np.unique(np.nonzero(redder > 25)[1])


def circular_error(a: float, b: float, width: int) -> float:
    d = abs(a - b) % width
    return min(d, width - d)


def column_of(pano: Panorama, azimuth: float) -> float:
    """The (fractional) column whose centre looks at body azimuth ``azimuth``."""
    return ((math.pi - azimuth) * pano.width_px / (2.0 * math.pi) - 0.5) % pano.width_px


def test_the_ball_shows_in_the_column_of_its_bearing(task: grab.GrabTask) -> None:
    assert task.panorama is not None
    for bearing_deg in (0.0, 60.0, 150.0, -100.0):
        b = math.radians(bearing_deg)
        _, cols = ball_columns(task, 0.0, b)
        assert 1 <= cols.size <= 3, (bearing_deg, cols)
        expected = column_of(task.panorama, b)
        assert circular_error(cols.mean(), expected, task.panorama.width_px) <= 1.0, (bearing_deg, cols)


def test_a_turn_on_the_spot_shifts_the_strip(task: grab.GrabTask) -> None:
    assert task.panorama is not None
    k = 8  # columns: 22.5 degrees on 128
    turn = 360.0 * k / task.panorama.width_px
    a = strip_at(task, 10.0, (500.0, 300.0)).astype(np.float64)
    b = strip_at(task, 10.0 + turn, (500.0, 300.0)).astype(np.float64)
    assert task.panorama.columns(math.radians(turn)) == pytest.approx(k)
    valid = task.panorama.valid  # the image's cut edges stay where they are: left out
    errors = []
    for shift in range(task.panorama.width_px):
        both = np.roll(valid, shift, axis=1) & valid
        errors.append(np.abs(np.roll(a, shift, axis=1) - b)[both].mean())
    assert int(np.argmin(errors)) == k
    assert errors[k] < 0.7 * errors[0]


def test_yaw_augmentation_turns_the_label_with_the_strip(task: grab.GrabTask) -> None:
    assert task.panorama is not None
    b = math.radians(40.0)
    strip, cols = ball_columns(task, 0.0, b)
    label = np.array([math.cos(b), math.sin(b), 0.3])  # toward the ball
    width = task.panorama.width_px
    for shift in (5, -20, 64):
        turned, v = yaw_augment(strip, label, shift)
        assert v[2] == 0.3 and np.array_equal(turned[:, (cols[0] - shift) % width], strip[:, cols[0]])
        expected = column_of(task.panorama, math.atan2(v[1], v[0]))
        assert circular_error(cols.mean() - shift, expected, width) <= 1.0, (shift, cols, expected)
    batch, vs = yaw_augment(np.stack([strip, strip]), np.stack([label, label]), 5)
    assert batch.shape == (2,) + strip.shape and vs.shape == (2, 3)


def test_a_floor_band_and_bad_settings() -> None:
    scenario = grab.default_scenario()
    floor = Panorama.of(scenario, floor_mm=(300.0, 1500.0), height_px=12, width_px=64)
    assert floor.floor_mm is not None and floor.elevation_rad is None
    assert floor.floor_mm[0] > floor.floor_mm[-1]  # far at the top
    assert floor.valid.mean() > 0.9
    with pytest.raises(ValueError, match="elevation_deg"):
        Panorama.of(scenario, elevation_deg=(10.0, -30.0))
    with pytest.raises(ValueError, match="width_px"):
        Panorama.of(scenario, width_px=2)
    with pytest.raises(ValueError, match="220 x 256 x 3"):
        floor(np.zeros((100, 100, 3), dtype=np.uint8))


def test_a_pinhole_camera_sees_only_ahead() -> None:
    scenario = omniloop.Scenario.load(ROOT / "scenarios" / "render_pinhole.toml")
    pano = Panorama.of(scenario, elevation_deg=(-30.0, 10.0))
    ahead = np.abs(pano.azimuth_rad) < math.radians(20.0)
    behind = np.abs(pano.azimuth_rad) > math.radians(120.0)
    assert pano.valid[:, ahead].any() and not pano.valid[:, behind].any()


def test_the_wrappers_and_the_pettingzoo_option() -> None:
    scenario = omniloop.Scenario.load(ROOT / "scenarios" / "blackout_stage1.toml")
    env = omniloop.gym.PanoramaObservation(
        gymnasium.make("omniloop/Scenario-v0", scenario=scenario), width_px=64, height_px=8
    )
    obs, _ = env.reset(seed=3)
    assert obs["omni"].shape == (8, 64, 3) and env.observation_space.contains(obs)
    venv = omniloop.gym.VectorPanoramaObservation(omniloop.gym.make_vec(scenario, 2), width_px=64, height_px=8)
    vobs, _ = venv.reset(seed=3)
    assert vobs["omni"].shape == (2, 8, 64, 3)
    assert np.array_equal(vobs["omni"][0], obs["omni"])  # the same frame, the same strip
    with pytest.raises(ValueError, match="sensors"):
        omniloop.gym.PanoramaObservation(gymnasium.make("omniloop/Scenario-v0", scenario=scenario), sensors=["nope"])
    from omniloop.pettingzoo import parallel_env

    penv = parallel_env(ROOT / "scenarios" / "swarm_swap.toml", panorama={"width_px": 32, "height_px": 4})
    pobs, _ = penv.reset(seed=1)
    agent = penv.possible_agents[0]
    first = next(k for k in pobs[agent] if k not in ("odometry", "goal"))
    assert pobs[agent][first].shape == (4, 32, 3)
    assert penv.observation_space(agent).contains(pobs[agent])


def test_placements_follow_the_rules() -> None:
    for seed in range(200):
        (rx, ry, h), (bx, by) = grab.placement(seed, "2019")
        assert abs(bx - rx) <= 500.0 and abs(by - ry) <= 500.0 and math.hypot(bx - rx, by - ry) >= 200.0
        assert abs(rx) + 500.0 <= 1700.0 and abs(ry) + 500.0 <= 1200.0 and -math.pi <= h <= math.pi
        (rx, ry, _), (bx, by) = grab.placement(seed, "2021")
        assert math.hypot(bx - rx, by - ry) >= 400.0 and max(abs(bx), abs(rx)) <= 1700.0
    assert grab.placement(7) == grab.placement(7) != grab.placement(8)
    with pytest.raises(ValueError, match="placements"):
        grab.placement(1, "2020")


def test_the_task_environment() -> None:
    from gymnasium.utils.env_checker import check_env

    env = gymnasium.make("omniloop/BlackoutGrab-v0", time_limit_s=5.0)
    check_env(env.unwrapped, skip_render_check=True)
    a, _ = env.reset(seed=11)
    b, _ = env.reset(seed=11)
    assert all(np.array_equal(a[k], b[k]) for k in a)
    assert set(a) == {"panorama", "odometry", "ball_in_dribbler"}  # never the truth
    with pytest.raises(ValueError, match="observation"):
        grab.GrabEnv(observation="truth")
    with pytest.raises(ValueError, match="stak=: no such setting"):
        gymnasium.make("omniloop/BlackoutGrab-v0", stak=3)


def test_the_task_runs_the_bundled_blackout_scenario() -> None:
    on_disk = omniloop.Scenario.load(ROOT / "scenarios" / "blackout_stage1.toml")
    assert grab.default_scenario().to_toml() == on_disk.to_toml()
    with pytest.raises(ValueError, match='no bundled scenario "nope": one of blackout_stage1'):
        omniloop.Scenario.bundled("nope")


def drive_to_ball(obs: dict[str, np.ndarray]) -> np.ndarray:
    """A hand-written policy on the privileged state: turn to the ball, then drive at it."""
    x, y = (float(v) for v in obs["state"])
    b = math.atan2(y, x)
    return np.array([0.5 if abs(b) < 0.3 else 0.0, 0.0, max(-1.0, min(1.0, b))])


def test_success_ends_the_episode_with_the_bonus() -> None:
    env = grab.GrabEnv(observation="state", time_limit_s=10.0)
    obs, _ = env.reset(seed=5)
    total, done = 0.0, False
    while not done:
        obs, r, term, trunc, info = env.step(drive_to_ball(obs))
        total += r
        done = term or trunc
    assert term and info["success"] and info["ball_in_dribbler"] and obs["ball_in_dribbler"][0] == 1.0
    assert total > 1.0  # the bonus and the distance made good
    assert 0.0 < info["time_s"] < 10.0


def test_a_wall_ends_the_episode_with_the_penalty() -> None:
    env = grab.GrabEnv(observation="state", time_limit_s=10.0)
    env.reset(seed=5)
    heading = env.sim.truth()["theta_rad"]
    term = False
    for _ in range(250):  # straight ahead in the world's +x, whatever the ball does
        c, s = math.cos(-heading), math.sin(-heading)
        _, r, term, trunc, info = env.step(np.array([c, s, 0.0]))
        if term or trunc:
            break
    assert term and info["wall_contact"] and not info["success"] and r < -0.5


def test_the_vector_task_gives_what_the_single_one_gives() -> None:
    single = grab.GrabEnv(time_limit_s=1.0)
    venv = grab.make_vec(2, time_limit_s=1.0)
    vobs, info = venv.reset(seed=[21, 22])
    sobs, _ = single.reset(seed=22)
    assert np.array_equal(vobs["panorama"][1], sobs["panorama"])
    seeds = []
    for _ in range(30):  # 1 s episodes: 25 steps, then the autoreset
        _, _, term, trunc, info = venv.step(np.zeros((2, 3)))
        seeds.append(tuple(info["seed"]))
    assert seeds[-1] == (23, 24)


@pytest.mark.long
def test_training_end_to_end_reproduces_its_weights(tmp_path: Path) -> None:
    script = str(ROOT / "python" / "examples" / "train_grab.py")

    # JAX's compilation cache, shared by the three trainings: the first compiles (16 s of its
    # 30 on this 2-core machine) and the other two load what it compiled. The weights it
    # reproduces are then the training's own determinism (seeds, batches, the simulation),
    # one compiled program run twice.
    cache = {
        "JAX_COMPILATION_CACHE_DIR": str(tmp_path / "jax-cache"),
        "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS": "0",
        "JAX_PERSISTENT_CACHE_MIN_ENTRY_SIZE_BYTES": "-1",
    }

    def start(out: Path, steps: int) -> subprocess.Popen[bytes]:
        cmd = [
            sys.executable, script, "--observation", "panorama", "--seeds", "3",
            "--steps", str(steps), "--envs", "4", "--n-steps", "64", "--eval-every", "256",
            "--curve-placements", "4", "--curve-limit-s", "1", "--eval-placements", "2",
            "--train-limit-s", "2", "--eval-limit-s", "2", "--out", str(out),
        ]
        return subprocess.Popen(cmd, cwd=tmp_path, env={**os.environ, **cache})

    def weights(out: Path, proc: subprocess.Popen[bytes]) -> dict[str, np.ndarray]:
        assert proc.wait(timeout=600) == 0, out
        return dict(np.load(out / "panorama" / "seed-3" / "weights.npz"))

    # The first alone, filling the cache; then the other two side by side.
    procs = {"a": start(tmp_path / "a", 512)}
    try:
        a = weights(tmp_path / "a", procs["a"])
        assert any((tmp_path / "jax-cache").iterdir()), "nothing compiled went to the cache"
        procs.update(b=start(tmp_path / "b", 512), c=start(tmp_path / "c", 0))
        b, untrained = (weights(tmp_path / name, procs[name]) for name in ("b", "c"))
    finally:
        for p in procs.values():
            p.kill()
    assert a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)
    assert not all(np.array_equal(untrained[k], a[k]) for k in a)
    rows = (tmp_path / "a" / "panorama" / "seed-3" / "curve.csv").read_text().splitlines()
    assert rows[0].startswith("env_steps") and len(rows) == 4  # 0, 256 and 512 steps
    result = json.loads((tmp_path / "a" / "panorama" / "seed-3" / "eval.json").read_text())
    assert set(result["eval"]) == {"2019", "2021"} and result["env_steps"] == 512
    assert result["eval"]["2019"]["count"] == 2 and result["eval"]["2019"]["limit_s"] == 2.0
    subprocess.run([sys.executable, script, "--plot", str(tmp_path / "a")], check=True, timeout=300)
    assert (tmp_path / "a" / "learning.png").stat().st_size > 10_000


def test_the_frame_stack_remembers_the_past_newest_first() -> None:
    plain = grab.GrabEnv(time_limit_s=2.0)
    stacked = grab.GrabEnv(time_limit_s=2.0, stack=3, stack_every=2)
    assert stacked.observation_space["panorama"].shape == (16, 128, 9)
    frames = [plain.reset(seed=4)[0]["panorama"]]
    obs = stacked.reset(seed=4)[0]["panorama"]
    assert all(np.array_equal(obs[..., 3 * j:3 * j + 3], frames[0]) for j in range(3))
    action = np.array([0.0, 0.0, 1.0])  # turn: every strip differs
    for t in range(1, 6):
        frames.append(plain.step(action)[0]["panorama"])
        obs = stacked.step(action)[0]["panorama"]
        for j in range(3):
            assert np.array_equal(obs[..., 3 * j:3 * j + 3], frames[max(t - 2 * j, 0)]), (t, j)
    venv = grab.make_vec(2, time_limit_s=2.0, stack=3, stack_every=2)
    vobs, _ = venv.reset(seed=[4, 5])
    assert np.array_equal(vobs["panorama"][0], stacked.reset(seed=4)[0]["panorama"])
    with pytest.raises(ValueError, match="stack"):
        grab.GrabEnv(stack=0)


def test_reset_takes_another_placement_of_the_same_robot() -> None:
    base = grab.default_scenario()
    moved = base.with_values({"robot.start.x_mm": 100.0, "robot.start.y_mm": -200.0})
    sim = omniloop.Simulation(base)
    sim.reset(seed=2, scenario=moved)
    assert (sim.truth()["x_mm"], sim.truth()["y_mm"]) == (100.0, -200.0)
    sim.reset()  # the last scenario stays
    assert sim.truth()["x_mm"] == 100.0 and sim.scenario.to_toml() == moved.to_toml()
    vec = omniloop.VectorSimulation(base, 2)
    vec.reset(1, 3, scenario=moved)
    assert vec.truth()[1]["x_mm"] == 100.0 and vec.truth()[0]["x_mm"] == -1200.0
    smaller = base.with_values({"robot.sensors": [{**_sensor(None), "name": "omni2"}]})
    for reset in (lambda: sim.reset(scenario=smaller), lambda: vec.reset(0, scenario=smaller)):
        with pytest.raises(ValueError, match="cameras"):
            reset()
    no_kicker = omniloop.Scenario.load(ROOT / "scenarios" / "smoke.toml")
    with pytest.raises(ValueError, match="other (kicker|cameras|drive)"):
        sim.reset(scenario=no_kicker)
