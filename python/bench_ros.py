"""Lockstep cycles per second through ROS 2 (DDS between two processes) beside
`Simulation.step` in-process, on the ROS smoke scene (one hyperbolic mirror camera at 256x220,
CPU renderer), and the latency from a frame's publication to the command that answers it.

    pip install './python[ros]'
    python python/bench_ros.py                 # 5 rounds of 20 s of simulated time each

The bridge runs as `omniloop-ros --lockstep` (every topic: image, camera_info, scan from the
free-space stage, odom, ground truth, /clock); a minimal rclpy node in this process answers
every `odom` with a `cmd_vel` turning the robot on the spot (so the run lasts its whole
duration), subscribed to the image and the scan as a vision node would be. In-process: the
same scenario, seed and command through `Simulation.step` with the frame handed to NumPy.
Rounds alternate between the two. Prints both rates, their ratio (target: the bridge keeps
>= 50%) and the latency's median and 95th percentile, as the bridge measures it.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

sys.path = [p for p in sys.path if Path(p or ".").resolve() != Path(__file__).resolve().parent]
import omniloop  # noqa: E402
from omniloop.ros import INSTALL_HINT  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "ros_smoke.toml"
TURN = (0.0, 0.0, 0.5)  # rad/s on the spot: the goal is never reached


def in_process(scenario: omniloop.Scenario) -> float:
    """Cycles per second of `Simulation.step` (Python as the robot), the whole run."""
    sim = omniloop.Simulation(scenario, frames=True)
    obs = sim.reset()
    t0 = time.perf_counter()
    while not obs.done:
        obs = sim.step(TURN)
        obs.frames["omni"]
    return sim.cycle / (time.perf_counter() - t0)


def through_ros(scenario_path: Path) -> tuple[float, float, float]:
    """One lockstep run of the bridge with an answering node: the bridge's cycles/s and the
    latency's median and p95 (ms), from its last log line."""
    import rclpy
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import Image, LaserScan

    script = Path(sys.executable).parent / "omniloop-ros"
    node = subprocess.Popen(
        [str(script), str(scenario_path), "--lockstep", "--exit-at-end"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    client = rclpy.create_node("bench_client")
    cmd = client.create_publisher(Twist, "/omniloop/cmd_vel", 10)
    answer = Twist()
    answer.angular.z = TURN[2]
    client.create_subscription(Odometry, "/omniloop/odom", lambda _m: cmd.publish(answer), 10)
    # What a vision node reads: the frame and the scan come through DDS each cycle.
    client.create_subscription(Image, "/omniloop/omni/image_raw", lambda _m: None, 10)
    client.create_subscription(LaserScan, "/omniloop/scan", lambda _m: None, 10)
    try:
        while node.poll() is None:
            rclpy.spin_once(client, timeout_sec=0.05)
        log = node.stdout.read()
    finally:
        client.destroy_node()
    m = re.search(
        r"\(([\d.]+) cycles/s\); frame to answering command: median ([\d.]+) ms, p95 ([\d.]+) ms",
        log,
    )
    if node.returncode != 0 or m is None:
        raise SystemExit(f"the bridge failed:\n{log}")
    return float(m.group(1)), float(m.group(2)), float(m.group(3))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    os.environ.setdefault("ROS_DOMAIN_ID", "77")
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    try:
        import rclpy
    except ImportError as e:
        raise SystemExit(f"{INSTALL_HINT} ({e})")

    scenario = omniloop.Scenario.load(SCENARIO)
    rclpy.init()
    local, runs = [], []
    try:
        # Interleaved, so that both see the machine as it is at the time.
        for k in range(args.rounds):
            local.append(in_process(scenario))
            runs.append(through_ros(SCENARIO))
            print(
                f"round {k + 1}: in-process {local[-1]:.1f}, bridge {runs[-1][0]:.1f} cycles/s",
                file=sys.stderr,
            )
    finally:
        rclpy.shutdown()
    ratio = statistics.median(r[0] / l for r, l in zip(runs, local))
    bridged = statistics.median(r[0] for r in runs)
    median_ms = statistics.median(r[1] for r in runs)
    p95_ms = statistics.median(r[2] for r in runs)
    print(f"{'':38}{'cycles/s':>10}")
    print(f"{'Simulation.step, in-process':38}{statistics.median(local):>10.1f}")
    print(f"{'omniloop-ros --lockstep, through DDS':38}{bridged:>10.1f}")
    print(f"bridge / in-process (median of the rounds' ratios): {ratio:.2f} (target >= 0.50)")
    print(f"frame to answering command: median {median_ms:.2f} ms, p95 {p95_ms:.2f} ms")
    print(f"({args.rounds} rounds, medians; {scenario.duration_s:g} s simulated a round)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
