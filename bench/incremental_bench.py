#!/usr/bin/env python3
"""No-op and one-file-change rebuilds with roc and colcon side by side.

    .venv/bin/python bench/incremental_bench.py [--sizes 20 100] [--skip-example] [--runs 3]

Each workspace is built once by each tool (in its own copy), then rebuilt without changes (no-op)
and after appending a comment to one C++ source of a package in the middle of the dependency graph
(one-file change). Targets: roc's no-op rebuild of 100 packages under 1 s; a one-file change costs
the rebuild of that package and its dependents plus under 1 s.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from build_bench import BIN, REPO, WORK, environment, fresh_copy, timed  # noqa: E402
from gen_workspace import ensure  # noqa: E402

COMMANDS = {"roc": [str(BIN / "roc"), "work", "build", "--parallel-workers", "2"],
            "colcon": [str(BIN / "colcon"), "build", "--parallel-workers", "2"]}


def middle_cpp_source(workspace: Path) -> Path:
    """A C++ source of a package with dependents, half-way through the topological order."""
    names = subprocess.run([str(BIN / "roc"), "work", "list", "-t", "-p"], cwd=workspace, env=environment(),
                           capture_output=True, text=True, check=True).stdout.split()
    for relative in names[len(names) // 2:] + names:
        sources = sorted((workspace / relative).rglob("*.cpp"))
        if sources:
            return sources[0]
    raise SystemExit(f"no C++ source in {workspace}")


def rebuilt_packages(workspace: Path) -> int:
    events = (workspace / "log" / "latest_build" / "events.log").read_text().splitlines()
    return len({json.loads(e)["task"] for e in events if json.loads(e)["event"] == "TaskStarted"})


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="*", default=[20, 100])
    parser.add_argument("--skip-example", action="store_true")
    parser.add_argument("--runs", type=int, default=3, help="no-op rebuilds per tool (median)")
    args = parser.parse_args(argv)
    workspaces = [] if args.skip_example else [("example", REPO / "workspaces" / "example")]
    for size in args.sizes:
        ensure(WORK / f"ws{size}", size)
        workspaces.append((f"synthetic-{size}", WORK / f"ws{size}"))
    print(f"{'workspace':<16}{'no-op roc':>11}{'no-op colcon':>14}{'ratio':>8}"
          f"{'1-file roc':>12}{'1-file colcon':>15}{'ratio':>8}{'rebuilt (roc)':>15}")
    for name, source in workspaces:
        row = {}
        for tool, command in COMMANDS.items():
            ws = fresh_copy(source, WORK / "incremental" / f"{name}-{tool}")
            timed(command, ws)
            row[f"noop_{tool}"] = statistics.median(timed(command, ws) for _ in range(args.runs))
            cpp = middle_cpp_source(ws)
            cpp.write_text(cpp.read_text() + "\n// changed\n")
            time.sleep(0.01)
            row[f"one_{tool}"] = timed(command, ws)
            if tool == "roc":
                row["rebuilt"] = rebuilt_packages(ws)
        print(f"{name:<16}{row['noop_roc']:>10.2f}s{row['noop_colcon']:>13.2f}s"
              f"{row['noop_roc'] / row['noop_colcon']:>8.3f}{row['one_roc']:>11.2f}s{row['one_colcon']:>14.2f}s"
              f"{row['one_roc'] / row['one_colcon']:>8.3f}{row['rebuilt']:>15}", flush=True)
    print("targets: no-op rebuild of 100 packages < 1 s; a one-file change = rebuild of the package and its "
          "dependents + < 1 s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
