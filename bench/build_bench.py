#!/usr/bin/env python3
"""Cold builds with roc and colcon side by side: the bundled example and synthetic workspaces.

    .venv/bin/python bench/build_bench.py [--sizes 20 100] [--workers 2] [--skip-example]

Each workspace is copied twice (one copy per tool, so neither reuses the other's build) and built from
scratch with ``--parallel-workers 2``. Reported per workspace: wall time of each tool, the ratio
roc/colcon (target <= 0.95), and each tool's orchestration overhead per package: wall time of a
sequential build minus the time spent inside the build tools (cmake, make, setup.py), divided by the
number of packages. The tool time is read from each tool's own command log (roc: events.log; colcon:
logger_all.log). Target: roc's overhead per package at most a third of colcon's.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time
from datetime import datetime
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
WORK = HERE / ".work"
BIN = Path(sys.executable).parent
sys.path.insert(0, str(HERE))

from gen_workspace import ensure  # noqa: E402


def environment() -> dict[str, str]:
    env = dict(os.environ)
    env["AMENT_PREFIX_PATH"] = sys.prefix
    env.pop("COLCON_PREFIX_PATH", None)
    env["PATH"] = f"{BIN}{os.pathsep}{env.get('PATH', '')}"
    return env


def fresh_copy(source: Path, destination: Path) -> Path:
    if destination.exists():
        shutil.rmtree(destination)
    shutil.copytree(source / "src", destination / "src")
    return destination


def timed(command: list[str], cwd: Path) -> float:
    start = time.perf_counter()
    result = subprocess.run(command, cwd=cwd, env=environment(), capture_output=True, text=True)
    elapsed = time.perf_counter() - start
    if result.returncode != 0:
        sys.exit(f"{' '.join(command)} failed in {cwd}:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
    return elapsed


def roc_tool_seconds(workspace: Path) -> float:
    """Seconds spent in commands, from roc's events.log (CommandStarted/CommandEnded pairs)."""
    started: dict[str, float] = {}
    total = 0.0
    for line in (workspace / "log" / "latest_build" / "events.log").read_text().splitlines():
        record = json.loads(line)
        if record["event"] == "CommandStarted":
            started[record["task"]] = record["time"]
        elif record["event"] == "CommandEnded":
            total += record["time"] - started.pop(record["task"])
    return total


_COLCON_LINE = re.compile(r"^\[(\d+\.\d+)s\] .*?(Invoking|Invoked) command in '([^']+)'")


def colcon_tool_seconds(workspace: Path) -> float:
    """Seconds spent in commands, from colcon's logger_all.log (Invoking/Invoked pairs by directory)."""
    started: dict[str, float] = {}
    total = 0.0
    for line in (workspace / "log" / "latest_build" / "logger_all.log").read_text().splitlines():
        match = _COLCON_LINE.match(line)
        if not match:
            continue
        stamp, kind, cwd = float(match.group(1)), match.group(2), match.group(3)
        if kind == "Invoking":
            started[cwd] = stamp
        elif cwd in started:
            total += stamp - started.pop(cwd)
    return total


def package_count(workspace: Path) -> int:
    result = subprocess.run([str(BIN / "roc"), "work", "list", "-n"], cwd=workspace, env=environment(),
                            capture_output=True, text=True, check=True)
    return len(result.stdout.split())


def bench_workspace(name: str, source: Path, workers: int, overhead: bool) -> dict:
    row: dict = {"workspace": name}
    commands = {
        "roc": [str(BIN / "roc"), "work", "build", "--parallel-workers", str(workers)],
        "colcon": [str(BIN / "colcon"), "build", "--parallel-workers", str(workers)],
    }
    for tool, command in commands.items():
        ws = fresh_copy(source, WORK / "build" / f"{name}-{tool}")
        row[tool] = timed(command, ws)
        row["packages"] = package_count(ws)
    row["ratio"] = row["roc"] / row["colcon"]
    if overhead:
        for tool, command in commands.items():
            sequential = [*command[:-2], "--executor", "sequential"]
            ws = fresh_copy(source, WORK / "build" / f"{name}-{tool}-seq")
            wall = timed(sequential, ws)
            tools = roc_tool_seconds(ws) if tool == "roc" else colcon_tool_seconds(ws)
            row[f"{tool}_overhead"] = (wall - tools) / row["packages"]
    return row


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="*", default=[20, 100])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--skip-example", action="store_true")
    parser.add_argument("--no-overhead", action="store_true", help="skip the sequential overhead runs")
    args = parser.parse_args(argv)
    workspaces = [] if args.skip_example else [("example", REPO / "workspaces" / "example")]
    for size in args.sizes:
        out = WORK / f"ws{size}"
        ensure(out, size)
        workspaces.append((f"synthetic-{size}", out))
    print(f"# cold builds, --parallel-workers {args.workers}, {datetime.now():%Y-%m-%d %H:%M}")
    print(f"{'workspace':<16}{'pkgs':>5}{'roc':>9}{'colcon':>9}{'roc/colcon':>12}{'ovh roc':>10}{'ovh colcon':>12}")
    for name, source in workspaces:
        row = bench_workspace(name, source, args.workers, not args.no_overhead)
        overhead = (f"{row['roc_overhead']:>9.3f}s{row['colcon_overhead']:>11.3f}s"
                    if "roc_overhead" in row else "")
        print(f"{name:<16}{row['packages']:>5}{row['roc']:>8.1f}s{row['colcon']:>8.1f}s{row['ratio']:>12.2f}{overhead}",
              flush=True)
    print("targets: roc/colcon <= 0.95; roc overhead per package <= 1/3 of colcon's")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
