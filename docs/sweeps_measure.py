"""The measurements behind docs/sweeps.md: engines' start-up, per-task overhead and memory,
and rides per hour through the sweep's runner.

    python docs/sweeps_measure.py trivial ENGINE [TASKS]        # ENGINE: local, dask, ray
    python docs/sweeps_measure.py rides ENGINE WORKERS RIDES    # 1.5 s rides of pd

``trivial``: a 2-worker pool or cluster started, then TASKS tasks returning their argument;
the memory is the resident set of this process and its children (psutil). ``rides``: Cassie
on the Hovershoes, pd, the ``push`` scenario cut to 1.5 s, seeds 0..RIDES-1, each through
the runner's ``ride_task`` (``ridempc.ride``, nothing written); the sweep's own time per ride
is ``elapsed * WORKERS / RIDES`` minus the mean time of the ``ride_task`` call in the worker.
Needs ``ridempc[cluster]`` for dask, and ``pip install ray`` for ray (not an extra of ridempc).
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path


def trivial(i: int) -> int:
    return i


def tree_rss_mib() -> float:
    import psutil

    me = psutil.Process(os.getpid())
    return sum(p.memory_info().rss for p in [me, *me.children(recursive=True)]) / 2**20


def measure_trivial(engine: str, tasks: int) -> str:
    t0 = time.perf_counter()
    if engine == "ray":
        import ray

        ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
        remote = ray.remote(num_cpus=1)(trivial)
        ray.get(remote.remote(-1))
        start = time.perf_counter() - t0
        t1 = time.perf_counter()
        ray.get([remote.remote(i) for i in range(tasks)])
        per_task = (time.perf_counter() - t1) / tasks
        rss = tree_rss_mib()
        ray.shutdown()
    else:
        from ridempc.sweep.engines import make_engine

        pool = make_engine(engine, 2, None)
        pool.submit(trivial, -1).result()
        start = time.perf_counter() - t0
        t1 = time.perf_counter()
        for future in [pool.submit(trivial, i) for i in range(tasks)]:
            future.result()
        per_task = (time.perf_counter() - t1) / tasks
        rss = tree_rss_mib()
        pool.close()
    return (
        f"{engine}: start-up {start:.2f} s, {1e3 * per_task:.2f} ms per trivial task, "
        f"{rss:.0f} MiB in this process and its children"
    )


def timed_ride(task):  # type: ignore[no-untyped-def]
    from ridempc.sweep.runner import ride_task

    t = time.perf_counter()
    summary = ride_task(task)
    summary["call_s"] = time.perf_counter() - t
    return summary


def measure_rides(engine: str, workers: int, rides: int) -> str:
    from ridempc.scenarios import resolve_scenario
    from ridempc.sweep.runner import RideTask, run_rides

    push = resolve_scenario("push", "hovershoes").with_duration(1.5)
    folder = Path(tempfile.mkdtemp())
    tasks = [
        RideTask(f"v{i:04d}", "pd", "cassie", "hovershoes", push, seed=i,
                 summary_path=folder / f"v{i:04d}.json")
        for i in range(rides)
    ]  # fmt: skip
    t0 = time.perf_counter()
    if engine == "ray":
        import ray

        ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
        remote = ray.remote(num_cpus=1)(timed_ride)
        start = time.perf_counter() - t0
        t1 = time.perf_counter()
        summaries = ray.get([remote.remote(t) for t in tasks])
        elapsed = time.perf_counter() - t1
        ray.shutdown()
    else:
        from ridempc.sweep.engines import make_engine

        pool = make_engine(engine, workers, None)
        start = time.perf_counter() - t0
        t1 = time.perf_counter()
        summaries = list(run_rides(tasks, pool, ride=timed_ride).values())
        elapsed = time.perf_counter() - t1
        pool.close()
    call = sum(s["call_s"] for s in summaries) / rides
    simulated = sum(s["wall_time_s"] for s in summaries) / rides
    overhead = elapsed * workers / rides - call
    memory = max(s["worker_peak_rss_mib"] for s in summaries)
    return (
        f"{engine} x{workers}: start-up {start:.2f} s; {rides} rides in {elapsed:.1f} s = "
        f"{3600 * rides / elapsed:.0f} rides/h; ride call {call:.2f} s (simulation "
        f"{simulated:.2f} s); sweep's own time per ride {overhead:.2f} s; worker peak "
        f"{memory:.0f} MiB"
    )


if __name__ == "__main__":
    if sys.argv[1] == "trivial":
        print(measure_trivial(sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 400))
    else:
        print(measure_rides(sys.argv[2], int(sys.argv[3]), int(sys.argv[4])))
