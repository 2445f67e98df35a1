"""Sweeps on a Ray cluster (``pip install omniloop[ray]``)::

    import ray, omniloop
    ray.init(address="auto")            # or ray.init() for this machine alone
    omniloop.sweep("scenarios/corner55_velocity_aware.toml",
                   sets={"robot.max_speed_mm_s": [400, 1000]}, seeds=100, executor="ray")

Each task runs a batch of planned jobs in its worker process with ``omniloop``'s own code
(the run on as many threads as the task has CPUs) and returns their records; the driver writes
each batch's records to the sweep's journal as it comes back. A task whose worker or node dies
is run again by Ray (``max_retries``); a run that fails is a record with its error. The
workers need ``omniloop`` installed and, when the scenario names other files (maps, camera
calibrations), those files at the same paths; ``keep_runs`` writes each run's files on the
machine that ran it.
"""

from __future__ import annotations

from typing import Callable, List, Optional, Sequence

import ray


def _run_batch(header: str, jobs: Sequence[str], keep: Optional[str], renderer: str) -> List[str]:
    """A Ray task: the planned jobs one after another in this worker; their records."""
    from omniloop import _omniloop

    cpus = ray.get_runtime_context().get_assigned_resources().get("CPU", 1.0)
    threads = max(1, int(round(cpus)))
    return [_omniloop.run_planned_job(header, job, keep, renderer, threads) for job in jobs]


class RayExecutor:
    """Runs a sweep's jobs as Ray tasks of ``batch_size`` jobs, each task asking for
    ``num_cpus`` CPUs and retried ``max_retries`` times when its worker dies. By default there
    are four tasks a CPU of the cluster (a task's scheduling costs milliseconds, more on a busy
    cluster, so fewer and longer tasks go faster), each taking every n-th job of the plan, so
    that every task holds a like share of the grid's slow and fast runs and the last tasks end
    together. ``address`` is given to ``ray.init`` when Ray is not initialized yet."""

    name = "ray"

    def __init__(
        self,
        batch_size: Optional[int] = None,
        num_cpus: float = 1,
        max_retries: int = 3,
        address: Optional[str] = None,
    ):
        if batch_size is not None and batch_size < 1:
            raise ValueError(f"batch_size={batch_size}: at least 1")
        self.batch_size = batch_size
        self.num_cpus = num_cpus
        self.max_retries = max_retries
        self.address = address

    def batches(self, jobs: Sequence[str]) -> List[Sequence[str]]:
        """The jobs cut into the tasks' batches, in the plan's order."""
        if self.batch_size is not None:
            size = self.batch_size
            return [jobs[i : i + size] for i in range(0, len(jobs), size)]
        cpus = max(1, int(ray.cluster_resources().get("CPU", 1) / self.num_cpus))
        tasks = max(1, min(len(jobs), 4 * cpus))
        return [jobs[k::tasks] for k in range(tasks)]

    def run(
        self,
        header: str,
        jobs: Sequence[str],
        keep: Optional[str],
        renderer: str,
        record: Callable[[str], None],
    ) -> None:
        """Runs ``jobs`` (the plan's lines after ``header``), handing each record to
        ``record`` as its batch comes back; Ctrl-C cancels the tasks not finished."""
        if not ray.is_initialized():
            ray.init(address=self.address)
        task = ray.remote(num_cpus=self.num_cpus, max_retries=self.max_retries)(_run_batch)
        pending = [task.remote(header, list(b), keep, renderer) for b in self.batches(jobs)]
        try:
            while pending:
                done, pending = ray.wait(pending, num_returns=1)
                for line in ray.get(done[0]):
                    record(line)
        except KeyboardInterrupt:
            for ref in pending:
                ray.cancel(ref, force=True)
            raise
