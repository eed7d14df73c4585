#!/usr/bin/env python3
"""``roc work build --cluster`` on this machine: one and two workers against a local build, each
worker pinned to one core, then the simulation beyond this machine.

    .venv/bin/python bench/cluster_bench.py [--packages 100] [--rounds 1]

On the synthetic workspace of gen_workspace.py (``bench/.work/ws<N>``), each round, every build in a
fresh copy and with a fresh remote cache (a new folder on one WebDAV server), cold:

1. ``local``: ``taskset -c 0 roc work build --parallel-workers 1 -j 1``: one core, no cluster;
2. ``1 worker``: a Dask scheduler and one ``roc work worker`` pinned to core 0 (``taskset -c 0``),
   ``roc work build --cluster --parallel-workers 1``;
3. ``2 workers``: two workers, on cores 0 and 1, ``--parallel-workers 2``.

Goals: 2 workers take <= 0.6x the time of 1; 1 worker <= 1.15x the local build (the cost of the
cluster). The per-task overhead: on the worker, the time beyond its build commands (restoring the
dependencies, uploading the archive), from the 1-worker run's events; between client and worker (sending
it, the result's return, restoring it into install/), the client's time beyond the worker's for each
package of a chain of six that compile nothing, built after it on the same worker (one at a time:
nothing waits in a queue). They go to
``bench/.work/cluster/overheads.json``, and cluster_sim.py replays the local build's durations with them
on 8, 32 and 128 workers (goal: within 10 % of the bound up to 32). The machine's load average is
printed before each build: it is shared, so repeat (``--rounds``) to see the spread.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import time
import uuid
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))

from build_bench import BIN, WORK, environment  # noqa: E402
from cluster_sim import from_workspace, report  # noqa: E402
from gen_workspace import ensure  # noqa: E402
from helpers.cluster import start_scheduler, start_worker, stop_all, wait_for_workers  # noqa: E402
from helpers.remote_servers import webdav  # noqa: E402

BASE = WORK / "cluster"


def load() -> str:
    one, five, _ = os.getloadavg()
    return f"load {one:.1f}/{five:.1f} (1/5 min, {os.cpu_count()} cores)"


def build(source: Path, name: str, command: list[str]) -> tuple[float, Path]:
    ws = BASE / name
    if ws.exists():
        shutil.rmtree(ws)
    shutil.copytree(source / "src", ws / "src")
    print(f"  {name:<10} {load()} ...", end="", flush=True)
    start = time.perf_counter()
    result = subprocess.run(command, cwd=ws, env=environment(), capture_output=True, text=True)
    elapsed = time.perf_counter() - start
    if result.returncode != 0:
        sys.exit(f"\n{' '.join(command)} failed in {ws}:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
    print(f" {elapsed:7.1f} s")
    return elapsed, ws


def cluster_build(source: Path, name: str, address: str, cache: str, workers: int, env: dict,
                  probe: bool = False) -> tuple[float, Path, float | None]:
    """A cold build on ``workers`` fresh workers, worker K pinned to core K, into a fresh cache; with
    ``probe``, then a chain of packages on them (the latency between client and worker)."""
    roots = BASE / f"{name}-roots"
    if roots.exists():
        shutil.rmtree(roots)
    started = []
    command = [str(BIN / "roc"), "work", "build", "--cluster", address, "--remote-cache", f"{cache}/{uuid.uuid4().hex}",
               "--parallel-workers", str(workers)]
    try:
        for index in range(workers):
            (roots / f"worker-{index}").mkdir(parents=True)
            started.append(start_worker(address, roots / f"worker-{index}", f"worker-{index}", env,
                                        prefix=("taskset", "-c", str(index))))
        wait_for_workers(address, {f"worker-{i}" for i in range(workers)}, processes=started)
        elapsed, ws = build(source, name, command)
        probed = None
        if probe:
            build(chain(BASE / "chain-src"), "chain", command)
            probed = latency(BASE / "chain")
        return elapsed, ws, probed
    finally:
        stop_all(started)


def _events(ws: Path) -> list[dict]:
    return [json.loads(line) for line in (ws / "log" / "latest_build" / "events.log").read_text().splitlines()]


def worker_overhead(ws: Path) -> float:
    """Per task of a cluster build, the worker's time beyond its build commands (restoring the
    dependencies, uploading the archive), in seconds."""
    commands: dict[str, list[float]] = {}
    extra = []
    for event in _events(ws):
        if event["event"] in ("CommandStarted", "CommandEnded"):
            commands.setdefault(event["task"], []).append(event["time"])
        elif event["event"] == "TaskFinished" and event.get("worker") and event["task"] in commands:
            times = commands[event["task"]]
            extra.append(event["duration"] - (max(times) - min(times)))
    return statistics.mean(extra)


def chain(base: Path, length: int = 6) -> Path:
    """A chain of packages that compile nothing, each on the one before: built on the cluster, one at a
    time, nothing waits in a queue."""
    if base.exists():
        shutil.rmtree(base)
    previous = ""
    for index in range(length):
        name = f"link_{index}_{uuid.uuid4().hex[:6]}"
        folder = base / "src" / name
        folder.mkdir(parents=True)
        depend = f"<depend>{previous}</depend>" if previous else ""
        (folder / "package.xml").write_text(
            f'<?xml version="1.0"?><package format="3"><name>{name}</name><version>0.0.1</version><description>'
            f'd</description><maintainer email="roc@example.com">roc</maintainer><license>Apache-2.0</license>'
            f"{depend}<export><build_type>cmake</build_type></export></package>")
        (folder / "CMakeLists.txt").write_text(f"cmake_minimum_required(VERSION 3.8)\nproject({name} NONE)\n"
                                               f"install(FILES package.xml DESTINATION share/{name})\n")
        previous = name
    return base


def latency(ws: Path) -> float:
    """Per task of a chain, the client's time beyond the worker's (sending it, the result's return,
    restoring it here), in seconds: the median."""
    started = {}
    gaps = []
    for event in _events(ws):
        if event["event"] == "TaskStarted":
            started[event["task"]] = event["time"]
        elif event["event"] == "TaskFinished" and event.get("worker"):
            gaps.append(event["time"] - started[event["task"]] - event["duration"])
    return statistics.median(gaps)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--packages", type=int, default=100)
    parser.add_argument("--rounds", type=int, default=1)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    if shutil.which("taskset") is None:
        sys.exit("cluster_bench needs taskset (util-linux)")
    source = WORK / f"ws{args.packages}"
    ensure(source, args.packages, args.seed)
    BASE.mkdir(parents=True, exist_ok=True)
    env = environment()
    rows = []
    (BASE / "dav").mkdir(exist_ok=True)
    with webdav(BASE / "dav") as port:
        scheduler, address = start_scheduler(BASE / "scheduler", env)
        try:
            for round_ in range(1, args.rounds + 1):
                print(f"round {round_}: {args.packages} packages")
                cache = f"http://127.0.0.1:{port}"
                local, local_ws = build(source, "local", ["taskset", "-c", "0", str(BIN / "roc"), "work", "build",
                                                          "--parallel-workers", "1", "-j", "1"])
                one, one_ws, between = cluster_build(source, "one", address, cache, 1, env, probe=True)
                two, _, _ = cluster_build(source, "two", address, cache, 2, env)
                overheads = {"worker_ms": 1000 * worker_overhead(one_ws), "latency_ms": 1000 * (between or 0.0)}
                rows.append({"local": local, "one": one, "two": two, **overheads})
                print(f"  2 workers / 1 worker: {two / one:.2f}x (goal <= 0.6x); 1 worker / local: "
                      f"{one / local:.2f}x (goal <= 1.15x); per task {overheads['worker_ms']:.0f} ms on the worker "
                      f"+ {overheads['latency_ms']:.0f} ms client-worker ({(one - local) / args.packages * 1000:.0f} ms "
                      f"a package all told)")
                (BASE / "overheads.json").write_text(json.dumps(overheads, indent=1))
                shutil.copytree(local_ws / "build", BASE / "local-build", dirs_exist_ok=True)
        finally:
            stop_all([scheduler])
    print("\nrounds:", json.dumps(rows, indent=1))
    graph, durations = from_workspace(local_ws)
    last = rows[-1]
    report(f"this machine's {args.packages}-package build on N workers", graph, durations, [1, 2, 8, 32, 128],
           last["worker_ms"] / 1000, last["latency_ms"] / 1000)
    return 0


if __name__ == "__main__":
    sys.exit(main())
