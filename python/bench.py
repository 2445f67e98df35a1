"""Steps per second from Python beside `omniloop run`'s cycles per second, on E1's corner scene
(the hyperbolic mirror camera at 256x220, CPU renderer), in one run.

    pip install ./python && cargo build --release
    python python/bench.py                    # all cores
    taskset -c 0 python python/bench.py       # one core

`pip` builds the extension in the workspace's `wheel` profile: `--cli target/wheel/omniloop`
(`cargo build --profile wheel`) compares it with the command line built alike.

Prints a table: the command line's cycles/s (`omniloop run`, from its summary.json: control
cycles alone), the same run through `omniloop.run`, `Simulation.step` with the built-in robot
(the same cycle, driven from Python: the overhead of the boundary) and with a Python robot
(a proportional controller toward the goal on dead reckoning: render, physics and the
frame handed to NumPy), and the vector environment's steps/s at 1, 4 and 16 runs, then with
the panorama observation (``omniloop.gym.VectorPanoramaObservation``) beside the raw image.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

# Run as `python python/bench.py`, Python puts this folder first on the path, where the
# package's sources lie without their native module: import the installed package instead.
sys.path = [p for p in sys.path if Path(p or ".").resolve() != Path(__file__).resolve().parent]
import omniloop  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "corner55_velocity_aware.toml"


def median_of(rounds: int, measure) -> float:
    return statistics.median(measure() for _ in range(rounds))


def cli_cycles_per_s(binary: Path) -> float:
    with tempfile.TemporaryDirectory() as out:
        subprocess.run(
            [str(binary), "run", str(SCENARIO), "--renderer", "cpu", "--quiet", "--out", out],
            check=True,
            cwd=ROOT,
            stdout=subprocess.DEVNULL,
        )
        return json.loads((Path(out) / "summary.json").read_text())["cycles_per_s"]


def library_cycles_per_s(scenario: omniloop.Scenario) -> float:
    return omniloop.run(scenario, renderer="cpu").summary["cycles_per_s"]


def builtin_steps_per_s(scenario: omniloop.Scenario) -> float:
    sim = omniloop.Simulation(scenario, robot="builtin")
    obs = sim.reset()
    start, steps = time.perf_counter(), 0
    while not obs.done:
        obs = sim.step()
        steps += 1
    return steps / (time.perf_counter() - start)


def toward(goal, pose, speed=400.0):
    """(vx, vy, omega) in the body frame toward `goal` from the dead-reckoned `pose`."""
    x, y, theta = pose
    dx, dy = goal[0] - x, goal[1] - y
    c, s = math.cos(theta), math.sin(theta)
    bx, by = c * dx + s * dy, -s * dx + c * dy
    d = max(math.hypot(bx, by), 1e-9)
    v = min(speed, 2.0 * d)
    return (v * bx / d, v * by / d, 0.0)


def python_steps_per_s(scenario: omniloop.Scenario, steps: int) -> float:
    g = scenario.robot["goal"]
    goal = (g["x_mm"], g["y_mm"])
    sim = omniloop.Simulation(scenario)
    obs = sim.reset()
    start, n = time.perf_counter(), 0
    while n < steps and not obs.done:
        obs = sim.step(toward(goal, obs.odometry_pose))
        n += 1
    return n / (time.perf_counter() - start)


def vector_steps_per_s(
    scenario: omniloop.Scenario, num_envs: int, steps: int, panorama: bool = False
) -> float:
    import omniloop.gym

    env = omniloop.gym.make_vec(scenario, num_envs=num_envs)
    if panorama:
        env = omniloop.gym.VectorPanoramaObservation(env)
    obs, _ = env.reset(seed=1)
    start = time.perf_counter()
    for _ in range(steps):
        goal = obs["goal"].astype(np.float64)
        d = np.maximum(np.linalg.norm(goal, axis=1, keepdims=True), 1e-9)
        v = np.minimum(400.0, 2.0 * d)
        actions = np.concatenate([v * goal / d, np.zeros((num_envs, 1))], axis=1)
        obs, *_ = env.step(actions)
    return num_envs * steps / (time.perf_counter() - start)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cli", type=Path, default=ROOT / "target" / "release" / "omniloop",
                    help="the omniloop binary (default: target/release/omniloop)")
    ap.add_argument("--rounds", type=int, default=3, help="medians of this many rounds")
    ap.add_argument("--steps", type=int, default=150, help="steps a round (vector, python)")
    ap.add_argument("--envs", default="1,4,16", help="vector sizes")
    ap.add_argument("--panorama-envs", type=int, default=16,
                    help="vector size of the panorama against the raw image")
    args = ap.parse_args()
    scenario = omniloop.Scenario.load(SCENARIO)
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    print(f"E1 corner scene (256x220, CPU renderer), {cores} core(s), medians of {args.rounds}",
          file=sys.stderr)
    rows = []
    if args.cli.is_file():
        cli = median_of(args.rounds, lambda: cli_cycles_per_s(args.cli))
        rows.append(("omniloop run (command line), cycles/s", cli, None))
    else:
        cli = None
        print(f"no {args.cli}: build it with `cargo build --release`", file=sys.stderr)
    lib = median_of(args.rounds, lambda: library_cycles_per_s(scenario))
    rows.append(("omniloop.run (same run from Python), cycles/s", lib, None))
    base = cli or lib
    builtin = median_of(args.rounds, lambda: builtin_steps_per_s(scenario))
    rows.append(("Simulation.step, robot=\"builtin\", steps/s", builtin, base / builtin - 1.0))
    py = median_of(args.rounds, lambda: python_steps_per_s(scenario, args.steps))
    rows.append(("Simulation.step, Python robot, steps/s", py, None))
    for n in (int(x) for x in args.envs.split(",")):
        v = median_of(args.rounds, lambda: vector_steps_per_s(scenario, n, args.steps))
        rows.append((f"vector env, {n} runs, env steps/s", v, None))
    # The panorama (omniloop.panorama, 128 x 16 by default) against the raw image, rounds
    # taken in turn so that both see the machine alike.
    n = args.panorama_envs
    raw, pano = [], []
    for _ in range(args.rounds):
        raw.append(vector_steps_per_s(scenario, n, args.steps))
        pano.append(vector_steps_per_s(scenario, n, args.steps, panorama=True))
    raw_v, pano_v = statistics.median(raw), statistics.median(pano)
    rows.append((f"vector env, {n} runs, raw image, env steps/s", raw_v, None))
    rows.append((f"vector env, {n} runs, panorama, env steps/s", pano_v, raw_v / pano_v - 1.0))
    print("| what | per second | step cost over the command line's cycle (panorama: over the raw image's step) |")
    print("|---|---:|---:|")
    for name, value, overhead in rows:
        extra = "" if overhead is None else f"{100.0 * overhead:+.1f}%"
        print(f"| {name} | {value:.1f} | {extra} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
