"""Sweeps from Python: one scenario over a grid of values and seeds, run on this machine's
cores (``executor="local"``, the same Rust pool as ``omniloop sweep``) or on a Ray cluster
(``executor="ray"``, see :mod:`omniloop.ray`).

::

    import omniloop

    result = omniloop.sweep(
        "scenarios/corner55_velocity_aware.toml",
        sets={"experiment.corner.angle_deg": "40..130:15", "robot.max_speed_mm_s": [400, 1000]},
        seeds=3,
    )
    print(result.success_rate, result.out / "sweep.md")

Every job is checked before anything runs (``ScenarioError`` names the key); the plan is
written to ``OUT/plan.jsonl``, each finished job to ``OUT/rows.jsonl`` as it ends, and the
report (``sweep.csv``, ``sweep.md``, ``sweep.png``) by the same code as the command line's.
``resume=True`` runs only the jobs ``rows.jsonl`` lacks. Ctrl-C stops starting jobs, writes
the report of what finished and raises ``KeyboardInterrupt``.
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping, Optional, Sequence, Union

from . import _omniloop

#: Columns that depend on the machine and its load, not on the run.
TIMING_COLUMNS = ("wall_time_s", "cycles_per_s", "renderer")


@dataclass
class SweepResult:
    """The rows of a sweep (``sweep.csv``'s columns, one dict a run) and where its files are."""

    rows: list[dict[str, Any]] = field(default_factory=list)
    out: Optional[Path] = None
    #: Seconds the jobs took on the executor, wall clock.
    wall_s: float = 0.0
    #: Jobs run now (not taken from a resumed journal).
    ran: int = 0

    @property
    def success_rate(self) -> float:
        """The share of runs that succeeded (no error, no contact, the goal when there is one)."""
        return sum(1 for r in self.rows if r["success"]) / max(1, len(self.rows))

    def failed(self) -> list[dict[str, Any]]:
        """The rows of runs that failed, with their ``error``."""
        return [r for r in self.rows if r["error"]]


class _Progress:
    """A progress bar on standard error: tqdm's when it is installed, a line otherwise."""

    def __init__(self, total: int, done: int, enabled: Union[bool, Callable[[int, int], Any]]):
        self.total, self.done, self.failed = total, done, 0
        self.callback = enabled if callable(enabled) else None
        self.bar = None
        if enabled is True:
            try:
                from tqdm import tqdm

                self.bar = tqdm(total=total, initial=done, unit="run", file=sys.stderr)
            except ImportError:
                self.bar = False

    def update(self, record: str) -> None:
        self.done += 1
        if json.loads(record).get("error"):
            self.failed += 1
        if self.bar:
            self.bar.update(1)
            if self.failed:
                self.bar.set_postfix(failed=self.failed)
        elif self.bar is False:
            print(f"\r{self.done}/{self.total} runs ({self.failed} failed)", end="", file=sys.stderr)
        if self.callback:
            self.callback(self.done, self.total)

    def close(self) -> None:
        if self.bar:
            self.bar.close()
        elif self.bar is False:
            print(file=sys.stderr)


def sweep(
    scenario: Union[str, Path],
    sets: Optional[Mapping[str, Any]] = None,
    seeds: Union[int, str, range] = 1,
    *,
    executor: Any = "local",
    out: Union[str, Path, None] = None,
    resume: bool = False,
    keep_runs: bool = False,
    jobs: int = 0,
    renderer: str = "cpu",
    plot: str = "success_rate",
    progress: Union[bool, Callable[[int, int], Any]] = True,
) -> SweepResult:
    """Runs ``scenario`` over every combination of ``sets`` and ``seeds``.

    - ``sets``: dotted keys (``"robot.max_speed_mm_s"``, ``"robot.sensors[0].noise_sigma"``),
      each with a list of values or a string as ``--set`` takes it (``"40..130:15"``).
    - ``seeds``: a count from the scenario's seed, ``"A..B"``, or a ``range`` (step 1).
    - ``executor``: ``"local"`` (this machine, ``jobs`` at a time, 0: one a core), ``"ray"``
      (a :class:`omniloop.ray.RayExecutor` on the cluster ``ray.init`` joined), or an executor.
    - ``out``: the sweep's folder (default ``runs/<name>_sweep``); ``keep_runs`` keeps each
      run's files in ``OUT/runs/NAME`` (on the machine that ran it).
    - ``progress``: a bar on standard error, ``False``, or ``callable(done, total)``.
    """
    if isinstance(seeds, range):
        if seeds.step != 1 or len(seeds) == 0:
            raise ValueError(f"seeds={seeds!r}: a range of step 1 with at least one seed")
        seeds = f"{seeds.start}..{seeds.stop - 1}"
    plan = _omniloop.sweep_plan(str(scenario), dict(sets or {}), str(seeds), out)
    out_dir, lines = Path(plan.out), plan.lines
    todo = plan.open(resume)
    total = len(lines) - 1
    bar = _Progress(total, total - len(todo), progress)
    start = time.perf_counter()
    interrupted = False
    try:
        if executor == "local":
            plan.run_local(jobs, renderer, keep_runs, bar.update)
        else:
            if executor == "ray":
                from .ray import RayExecutor

                executor = RayExecutor()
            journal = out_dir / "rows.jsonl"
            keep = str(out_dir / "runs") if keep_runs else None
            with journal.open("a", encoding="utf-8") as f:

                def record(line: str) -> None:
                    f.write(line + "\n")
                    f.flush()
                    bar.update(line)

                executor.run(lines[0], [lines[1 + i] for i in todo], keep, renderer, record)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        bar.close()
    wall_s = time.perf_counter() - start
    ran = bar.done - (total - len(todo))
    name = getattr(executor, "name", executor)
    header = (
        f"{ran} of {total} runs"
        + (f", {total - len(todo)} more from the sweep resumed" if len(todo) < total else "")
        + (", stopped by Ctrl-C" if interrupted else "")
        + f", executor {name}: {wall_s:.1f} s, {ran / max(wall_s, 1e-9):.2f} runs/s."
    )
    rows = json.loads(plan.report(plot, header))
    if interrupted:
        raise KeyboardInterrupt(f"sweep stopped; what finished is in {out_dir}")
    return SweepResult(rows=rows, out=out_dir, wall_s=wall_s, ran=ran)


def without_timing(rows: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """The rows without the columns that depend on the machine (to compare two sweeps)."""
    return [{k: v for k, v in r.items() if k not in TIMING_COLUMNS} for r in rows]
