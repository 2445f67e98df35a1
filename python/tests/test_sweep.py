"""`omniloop.sweep`: on this machine's pool and on a Ray cluster of two nodes (one lost part-way),
the same rows, the same runs as alone; resumed, only the missing jobs run; a bad key raises."""

import json
import os
from pathlib import Path

import pytest

import omniloop
from omniloop.sweeps import without_timing

from conftest import SCENARIOS

# Ray's nodes on this machine's loopback interface only (read when Ray is first imported).
os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"

E1 = SCENARIOS / "corner55_velocity_aware.toml"
SMALL = {"robot.max_speed_mm_s": [300, 400]}
#: A 24-run part of docs/sweeps.md's corner sweep.
CORNER = {"experiment.corner.angle_deg": [40, 55, 70, 85], "robot.max_speed_mm_s": "400,1000"}


def trajectories(out: Path) -> dict:
    """Each kept run's trajectory.csv bytes, by run folder name."""
    return {d.name: (d / "trajectory.csv").read_bytes() for d in sorted((out / "runs").iterdir())}


def test_a_local_sweep_writes_the_report_and_its_rows_are_the_runs_alone(tmp_path, corner):
    result = omniloop.sweep(E1, SMALL, seeds=2, out=tmp_path / "s", keep_runs=True, progress=False)
    assert [r["robot.max_speed_mm_s"] for r in result.rows] == [300, 300, 400, 400]
    assert [r["seed"] for r in result.rows] == [55, 56, 55, 56]
    for f in ("plan.jsonl", "rows.jsonl", "sweep.csv", "sweep.md", "sweep.png"):
        assert (result.out / f).is_file(), f
    assert result.ran == 4 and result.success_rate == 1.0
    # The last row again, alone.
    alone = omniloop.run(corner.with_values({"robot.max_speed_mm_s": 400}), seed=56, out=tmp_path / "a")
    assert alone.summary["cycles"] == result.rows[3]["cycles"]
    assert alone.summary["path_length_mm"] == result.rows[3]["path_length_mm"]
    runs = trajectories(result.out)
    assert (tmp_path / "a" / "trajectory.csv").read_bytes() == runs["0003_max_speed_mm_s=400_seed=56"]


def test_a_resumed_sweep_runs_only_what_its_journal_lacks(tmp_path):
    out = tmp_path / "s"
    first = omniloop.sweep(E1, SMALL, seeds=2, out=out, progress=False)
    journal = out / "rows.jsonl"
    lines = journal.read_text().splitlines()
    journal.write_text(lines[1] + "\n" + lines[2] + "\n")
    again = omniloop.sweep(E1, SMALL, seeds=2, out=out, resume=True, progress=False)
    assert again.ran == 2
    assert without_timing(again.rows) == without_timing(first.rows)
    assert "2 more from the sweep resumed" in (out / "sweep.md").read_text()
    assert sorted(json.loads(l)["index"] for l in journal.read_text().splitlines()) == [0, 1, 2, 3]


def test_a_bad_key_raises_before_anything_runs(tmp_path):
    with pytest.raises(omniloop.ScenarioError, match="max_speed_mm_s"):
        omniloop.sweep(E1, {"robot.max_speed_mm_s": [400, -5]}, out=tmp_path / "bad", progress=False)
    assert not (tmp_path / "bad" / "rows.jsonl").exists()


@pytest.mark.long
def test_a_ray_cluster_of_two_nodes_losing_one_gives_the_local_sweeps_rows(tmp_path):
    import ray  # in the test extra: pip install ./python[test]
    from ray.cluster_utils import Cluster

    from omniloop.ray import RayExecutor

    local = omniloop.sweep(E1, CORNER, seeds=3, out=tmp_path / "local", keep_runs=True, progress=False)
    assert len(local.rows) == 24
    cluster = Cluster(
        initialize_head=True,
        head_node_args={
            "num_cpus": 1,
            "include_dashboard": False,
            "_system_config": {"health_check_period_ms": 500, "health_check_failure_threshold": 4},
        },
    )
    second = cluster.add_node(num_cpus=1)
    ray.init(address=cluster.address, include_dashboard=False, log_to_driver=False)
    removed = []

    def lose_a_node(done: int, total: int) -> None:
        if done == 6 and not removed:
            cluster.remove_node(second)
            removed.append(done)

    try:
        assert ray.cluster_resources()["CPU"] == 2
        result = omniloop.sweep(
            E1,
            CORNER,
            seeds=3,
            executor=RayExecutor(batch_size=1),
            out=tmp_path / "ray",
            keep_runs=True,
            progress=lose_a_node,
        )
    finally:
        ray.shutdown()
        cluster.shutdown()
    assert removed == [6]
    assert len(result.rows) == 24 and not result.failed()
    assert without_timing(result.rows) == without_timing(local.rows)
    assert trajectories(result.out) == trajectories(local.out)
