"""`omniloop.run`: the built-in robot as `omniloop run` runs it."""

import csv
import math

import numpy as np
import pytest

import omniloop


def test_run_returns_the_summary_and_the_trajectory_it_writes(smoke, tmp_path):
    result = omniloop.run(smoke, seed=11, out=tmp_path)
    s = result.summary
    assert s["scenario"] == "smoke" and s["seed"] == 11
    assert s["reached_goal"] is True and s["wall_contacts"] == 0
    assert result.out == tmp_path
    for name in ("summary.json", "trajectory.csv", "estimates.jsonl", "topview.png"):
        assert (tmp_path / name).is_file(), name
    with open(tmp_path / "trajectory.csv") as f:
        rows = list(csv.reader(f))
    header, rows = rows[0], rows[1:]
    assert list(result.trajectory) == header
    assert len(result.trajectory["t_s"]) == len(rows) == s["cycles"] + 1
    for k, name in enumerate(header):
        column = result.trajectory[name]
        assert column.dtype == np.float64
        written = [float(r[k]) if r[k] else math.nan for r in rows]
        np.testing.assert_array_equal(column, np.array(written), err_msg=name)


def test_the_same_seed_gives_the_same_trajectory(smoke):
    a = omniloop.run(smoke, seed=5).trajectory
    b = omniloop.run(smoke, seed=5).trajectory
    for name in a:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


def test_progress_is_reported_in_order(smoke):
    calls = []
    omniloop.run(smoke, progress=lambda cycle, total: calls.append((cycle, total)))
    assert 10 <= len(calls) <= 101
    cycles = [c for c, _ in calls]
    assert cycles == sorted(cycles) and calls[0][0] >= 1
    assert all(total == smoke.max_cycles for _, total in calls)


def test_an_error_in_the_progress_callback_reaches_the_caller(smoke):
    def fail(cycle, total):
        raise KeyError("stop")

    with pytest.raises(KeyError, match="stop"):
        omniloop.run(smoke, progress=fail)
