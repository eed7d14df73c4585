#!/usr/bin/env python3
"""What ``roc work build --cluster`` would take on N workers, beyond what this machine can show.

    .venv/bin/python bench/cluster_sim.py [--workspace DIR] [--synthetic 400] [--workers 1,2,4,...,128]
                                          [--overheads bench/.work/cluster/overheads.json]

Replays a workspace's package durations on N simulated workers with roc's own ready-queue policy
(``roc.engine.ready.ReadyQueue``: Kahn's algorithm, the longest remaining chain first), each task
costing, besides its build, the per-task overheads ``bench/cluster_bench.py`` measured on the real
cluster: on the worker, restoring its dependencies and uploading its archive (``worker`` seconds);
between client and worker, sending it and restoring the result into the client's install tree
(``latency`` seconds, which delays its dependents but keeps no worker busy). Prints the makespan
against the bound max(critical path, total work / N) of the same task times, and the ideal
(durations alone, no overhead).

- ``--workspace DIR``: a workspace roc built (its packages and dependencies as roc finds them, its
  durations from ``DIR/build/roc_durations.json``, as roc stores them after every build);
- ``--synthetic N`` (default 400): a workspace shaped like a large real one (Autoware's kind): deep
  chains of interface packages at the bottom, libraries on them, and many leaves (nodes, launch and
  Python packages) nothing depends on, with durations drawn from the shares such workspaces show.
"""

from __future__ import annotations

import argparse
import heapq
import json
import random
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from roc.engine.ready import ReadyQueue, Task  # noqa: E402

DEFAULT_WORKERS = (1, 2, 4, 8, 16, 32, 64, 128)
DEFAULT_OVERHEADS = HERE / ".work" / "cluster" / "overheads.json"


def synthetic(packages: int, seed: int = 0) -> tuple[dict[str, set[str]], dict[str, float]]:
    """A large real workspace's shape: 10 % interface packages in deep chains (rosidl: slow), 30 %
    libraries on them, 60 % leaves; durations log-normal around what such packages take on one core."""
    rng = random.Random(seed)
    interfaces = [f"msgs_{i:03d}" for i in range(max(1, packages // 10))]
    libraries = [f"lib_{i:03d}" for i in range(packages * 3 // 10)]
    leaves = [f"node_{i:03d}" for i in range(packages - len(interfaces) - len(libraries))]
    graph: dict[str, set[str]] = {}
    durations: dict[str, float] = {}
    chains = max(1, len(interfaces) // 8)  # chains of about 8 interface packages, each on the one before it
    for index, name in enumerate(interfaces):  # and sometimes on an earlier one of another chain
        before = interfaces[index - chains] if index >= chains else None
        graph[name] = {before} if before else set()
        if index >= chains and rng.random() < 0.3:
            graph[name].add(rng.choice(interfaces[:index - chains + 1]))
        durations[name] = rng.lognormvariate(3.6, 0.4)  # median ~37 s (rosidl's generators and compiles)
    for index, name in enumerate(libraries):
        graph[name] = set(rng.sample(interfaces, rng.randint(1, 4)))
        graph[name] |= set(rng.sample(libraries[:index], min(index, rng.randint(0, 3))))
        durations[name] = rng.lognormvariate(3.3, 0.8)  # median ~27 s, a long tail
    for name in leaves:
        graph[name] = set(rng.sample(interfaces, rng.randint(0, 3))) | set(rng.sample(libraries, rng.randint(1, 4)))
        python = rng.random() < 0.3
        durations[name] = rng.lognormvariate(1.2, 0.4) if python else rng.lognormvariate(3.1, 0.6)
    return graph, durations


def from_workspace(root: Path) -> tuple[dict[str, set[str]], dict[str, float]]:
    """A workspace roc built: its packages' workspace dependencies, and the durations roc stored."""
    from roc.workspace.dependencies import topological_order
    from roc.workspace.load import discover_workspace

    packages = topological_order(discover_workspace(root))
    names = {p.name for p in packages}
    stored = json.loads((root / "build" / "roc_durations.json").read_text())
    graph = {p.name: p.direct_dependencies() & names for p in packages}
    missing = sorted(n for n in graph if n not in stored)
    if missing:
        sys.exit(f"{root}/build/roc_durations.json has no duration for {', '.join(missing[:5])}: build it first")
    return graph, {name: float(stored[name]) for name in graph}


def critical_path(graph: dict[str, set[str]], cost: dict[str, float], latency: float = 0.0) -> float:
    """The longest chain of task costs (each link also paying ``latency``)."""
    longest: dict[str, float] = {}
    ready = ReadyQueue({n: Task(n, deps, action=None) for n, deps in graph.items()})
    while ready.has_ready():
        name = ready.pop().name
        longest[name] = cost[name] + latency + max((longest[d] for d in graph[name]), default=0.0)
        ready.done(name)
    return max(longest.values(), default=0.0)


def simulate(graph: dict[str, set[str]], durations: dict[str, float], workers: int, worker_overhead: float = 0.0,
             latency: float = 0.0) -> float:
    """The makespan of the build on ``workers`` workers with roc's ready queue: a free worker takes
    the ready task with the longest remaining chain; it stays busy for the task's duration plus
    ``worker_overhead``; its dependents become ready ``latency`` later."""
    queue = ReadyQueue({n: Task(n, deps, action=None, weight=durations[n]) for n, deps in graph.items()})
    events: list[tuple[float, int, str]] = []  # (time, 0 = worker free / 1 = done, task)
    free, now = workers, 0.0
    while True:
        while free and queue.has_ready():
            task = queue.pop()
            busy = now + durations[task.name] + worker_overhead
            heapq.heappush(events, (busy, 0, task.name))
            heapq.heappush(events, (busy + latency, 1, task.name))
            free -= 1
        if not events:
            return now
        now, kind, name = heapq.heappop(events)
        if kind == 0:
            free += 1
        else:
            queue.done(name)


def report(title: str, graph: dict[str, set[str]], durations: dict[str, float], counts: list[int],
           worker_overhead: float, latency: float) -> list[dict]:
    cost = {n: d + worker_overhead for n, d in durations.items()}
    path = critical_path(graph, cost, latency)
    ideal_path = critical_path(graph, durations)
    total, ideal_total = sum(cost.values()), sum(durations.values())
    print(f"\n{title}: {len(graph)} packages, total work {ideal_total:.0f} s, critical path {ideal_path:.0f} s; "
          f"per task {worker_overhead * 1000:.0f} ms on the worker + {latency * 1000:.0f} ms between client and worker")
    print(f"{'workers':>7} {'makespan':>10} {'bound':>10} {'makespan/bound':>15} {'ideal':>10} {'speed-up':>9}")
    rows = []
    one = simulate(graph, durations, 1, worker_overhead, latency)
    for n in counts:
        makespan = simulate(graph, durations, n, worker_overhead, latency)
        bound = max(path, total / n)
        ideal = max(ideal_path, ideal_total / n)
        rows.append({"workers": n, "makespan": makespan, "bound": bound, "ratio": makespan / bound, "ideal": ideal})
        print(f"{n:>7} {makespan:>9.1f}s {bound:>9.1f}s {makespan / bound:>14.3f}x {ideal:>9.1f}s "
              f"{one / makespan:>8.1f}x")
    return rows


def overheads(path: Path, given: list[float] | None) -> tuple[float, float, str]:
    if given:
        return given[0] / 1000, given[1] / 1000, "given"
    try:
        measured = json.loads(path.read_text())
        return measured["worker_ms"] / 1000, measured["latency_ms"] / 1000, f"measured ({path})"
    except (OSError, ValueError, KeyError):
        return 0.5, 0.3, "assumed (run bench/cluster_bench.py to measure them)"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--workspace", type=Path, help="a workspace roc built (its build/roc_durations.json)")
    parser.add_argument("--synthetic", type=int, default=400, help="packages of the synthetic workspace (0: none)")
    parser.add_argument("--workers", default=",".join(map(str, DEFAULT_WORKERS)), help="worker counts to simulate")
    parser.add_argument("--overheads", type=Path, default=DEFAULT_OVERHEADS, help="cluster_bench.py's measurements")
    parser.add_argument("--overhead-ms", type=float, nargs=2, metavar=("WORKER", "LATENCY"),
                        help="per-task overheads instead of the measured ones")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    counts = [int(n) for n in args.workers.split(",")]
    worker_overhead, latency, source = overheads(args.overheads, args.overhead_ms)
    print(f"per-task overheads {source}")
    if args.synthetic:
        graph, durations = synthetic(args.synthetic, args.seed)
        report(f"synthetic workspace (seed {args.seed})", graph, durations, counts, worker_overhead, latency)
    if args.workspace:
        graph, durations = from_workspace(args.workspace.resolve())
        report(str(args.workspace), graph, durations, counts, worker_overhead, latency)
    return 0


if __name__ == "__main__":
    sys.exit(main())
