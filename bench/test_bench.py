#!/usr/bin/env python3
"""A second, cached ``roc work test`` against ``colcon test``, side by side in one run.

    .venv/bin/python bench/test_bench.py [--workspace example|testing] [--runs 5]

The workspace (workspaces/example by default, or the ``testing`` fixture) is copied to bench/.work/,
built once with roc and tested once with roc (which records the passing results). Then ``colcon test``
and ``roc work test`` alternate ``--runs`` times; the medians and their ratio are printed. colcon
reruns every test each time; roc reruns only the packages whose tests failed or whose inputs changed.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from build_bench import BIN, REPO, WORK, environment, fresh_copy  # noqa: E402

SOURCES = {"example": REPO / "workspaces" / "example", "testing": REPO / "workspaces" / "fixtures" / "testing"}


def run_timed(command: list[str], cwd: Path) -> float:
    """Seconds of one run (test failures are expected in the testing fixture: exit codes are not checked)."""
    import time

    start = time.perf_counter()
    subprocess.run(command, cwd=cwd, env=environment(), capture_output=True, text=True)
    return time.perf_counter() - start


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workspace", choices=sorted(SOURCES), default="example")
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args(argv)
    workspace = fresh_copy(SOURCES[args.workspace], WORK / f"test_{args.workspace}")
    subprocess.run([str(BIN / "roc"), "work", "build"], cwd=workspace, env=environment(), check=True,
                   capture_output=True)
    roc = [str(BIN / "roc"), "work", "test"]
    colcon = [str(BIN / "colcon"), "test"]
    run_timed(roc, workspace)  # the first run records the passing results
    times: dict[str, list[float]] = {"roc": [], "colcon": []}
    for _ in range(args.runs):
        times["colcon"].append(run_timed(colcon, workspace))
        times["roc"].append(run_timed(roc, workspace))
    roc_median, colcon_median = statistics.median(times["roc"]), statistics.median(times["colcon"])
    print(f"workspace {args.workspace}: colcon test {colcon_median:.2f} s, cached roc work test "
          f"{roc_median:.2f} s (median of {args.runs}); colcon/roc = {colcon_median / roc_median:.1f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
