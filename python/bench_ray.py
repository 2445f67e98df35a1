"""A sweep's throughput on a Ray cluster of one and of two one-CPU nodes on this machine, and
the driver's overhead per job, side by side in one run.

    pip install "./python[ray]"
    python python/bench_ray.py                # the corner sweep, 48 runs, three rounds

The sweep is docs/sweeps.md's corner over four angles and two speeds, six seeds each (48 runs of
E1, CPU renderer, each run on its task's one CPU). Throughput is runs per second of the whole
sweep, wall clock on the driver (plan, tasks, journal, report). The driver's overhead per job is
what a job costs beyond its own run on one node: (the sweep's wall time - the sum of the runs'
own wall times) / runs.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
from pathlib import Path

# Ray's nodes on this machine's loopback interface only (read when Ray is first imported).
os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"
sys.path = [p for p in sys.path if Path(p or ".").resolve() != Path(__file__).resolve().parent]
import omniloop  # noqa: E402
import ray  # noqa: E402
from omniloop.ray import RayExecutor  # noqa: E402
from ray.cluster_utils import Cluster  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "corner55_velocity_aware.toml"
SETS = {"experiment.corner.angle_deg": [40, 55, 70, 85], "robot.max_speed_mm_s": [400, 1000]}


def one_sweep(nodes: int, seeds: int, batch_size) -> tuple:
    """The sweep on a fresh cluster of `nodes` one-CPU nodes: (runs/s, overhead ms a job, a
    run's own mean wall time in s)."""
    cluster = Cluster(
        initialize_head=True, head_node_args={"num_cpus": 1, "include_dashboard": False},
    )
    for _ in range(nodes - 1):
        cluster.add_node(num_cpus=1)
    ray.init(address=cluster.address, include_dashboard=False, log_to_driver=False)
    try:
        # A worker on every node imports omniloop before the clock starts.
        warm = ray.remote(num_cpus=1, scheduling_strategy="SPREAD")(
            lambda: __import__("omniloop").__version__
        )
        ray.get([warm.remote() for _ in range(2 * nodes)])
        with tempfile.TemporaryDirectory() as out:
            r = omniloop.sweep(
                SCENARIO,
                SETS,
                seeds=seeds,
                executor=RayExecutor(batch_size=batch_size),
                out=out,
                progress=False,
            )
    finally:
        ray.shutdown()
        cluster.shutdown()
    assert not r.failed(), r.failed()
    runs = len(r.rows)
    own = sum(row["wall_time_s"] for row in r.rows)
    return runs / r.wall_s, 1e3 * (r.wall_s - own / nodes) / runs, own / runs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=6)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--batch-size", type=int, default=None)
    a = ap.parse_args()
    one, two, over1, over2, own1, own2 = [], [], [], [], [], []
    for k in range(a.rounds):
        t1, o1, r1 = one_sweep(1, a.seeds, a.batch_size)
        t2, o2, r2 = one_sweep(2, a.seeds, a.batch_size)
        one.append(t1)
        two.append(t2)
        over1.append(o1)
        over2.append(o2)
        own1.append(r1)
        own2.append(r2)
        print(f"round {k + 1}: one node {t1:.2f} runs/s, two nodes {t2:.2f} runs/s ({t2 / t1:.2f}x)")
    m1, m2 = statistics.median(one), statistics.median(two)
    runs = 8 * a.seeds
    print(f"\ncorner sweep, {runs} runs, median of {a.rounds} rounds (omniloop {omniloop.__version__}, ray {ray.__version__}):")
    print(f"  one 1-CPU node    {m1:6.2f} runs/s")
    print(f"  two 1-CPU nodes   {m2:6.2f} runs/s   {m2 / m1:.2f}x")
    print(f"  driver overhead   {statistics.median(over1):6.1f} ms a job on one node, "
          f"{statistics.median(over2):.1f} ms on two")
    print(f"  a run's own time  {1e3 * statistics.median(own1):6.0f} ms on one node, "
          f"{1e3 * statistics.median(own2):.0f} ms on two (two runs at once)")


if __name__ == "__main__":
    main()
