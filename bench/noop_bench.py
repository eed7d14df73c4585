#!/usr/bin/env python3
"""The floor of a no-op ``roc work build``: side by side with Python's own start.

    .venv/bin/python bench/noop_bench.py [--packages 100] [--runs 15]

In ``bench/.work/ws<N>`` (generated, and built once by roc when it is not yet), in the ``boot``
environment of list_bench.py (no re-exec through the ROS wheels' bootstrapper), the runs of these
commands are interleaved, each timed with ``time.perf_counter`` around ``subprocess.run``:

* ``python -S -c pass``: the interpreter alone;
* ``python -c pass``: with site and the venv's ``.pth`` files (the limit any Python tool starts from);
* ``python -c 'import roc.cli.main'``: roc's entry point imported;
* ``roc work build``: the no-op build (every package up to date; target <= 0.12 s at 100 packages).

Prints the median and minimum of each and the ratio of roc's no-op to Python's start (medians).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from build_bench import BIN, WORK, environment  # noqa: E402
from gen_workspace import ensure  # noqa: E402
from list_bench import BOOT_FLAG, wheel_library_path  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--packages", type=int, default=100)
    parser.add_argument("--runs", type=int, default=15)
    args = parser.parse_args(argv)
    workspace = WORK / f"ws{args.packages}"
    if ensure(workspace, args.packages) or not (workspace / "install").is_dir():
        print(f"building {workspace} once (minutes)", flush=True)
        subprocess.run([str(BIN / "roc"), "work", "build", "--parallel-workers", "2"], cwd=workspace,
                       env=environment(), capture_output=True, check=True)
    env = {**environment(), BOOT_FLAG: "1", "LD_LIBRARY_PATH": wheel_library_path(Path(sys.prefix))}
    python = str(BIN / "python")
    commands = {
        "python -S -c pass": [python, "-S", "-c", "pass"],
        "python -c pass": [python, "-c", "pass"],
        "import roc.cli.main": [python, "-c", "import roc.cli.main"],
        "roc work build (no-op)": [str(BIN / "roc"), "work", "build"],
    }
    check = subprocess.run(commands["roc work build (no-op)"], cwd=workspace, env=env, capture_output=True, text=True)
    if check.returncode != 0 or f"{args.packages} packages up to date" not in check.stdout:
        sys.exit(f"the no-op build is not a no-op:\n{check.stdout[-2000:]}{check.stderr[-2000:]}")
    times: dict[str, list[float]] = {name: [] for name in commands}
    for _ in range(args.runs):
        for name, command in commands.items():
            start = time.perf_counter()
            subprocess.run(command, cwd=workspace, env=env, capture_output=True, check=True)
            times[name].append(time.perf_counter() - start)
    print(f"# {args.packages} packages, {args.runs} runs each, load {os.getloadavg()[0]:.1f}")
    print(f"{'command':<26}{'median':>9}{'min':>9}")
    for name, values in times.items():
        print(f"{name:<26}{statistics.median(values):>8.3f}s{min(values):>8.3f}s")
    noop, start = statistics.median(times["roc work build (no-op)"]), statistics.median(times["python -c pass"])
    print(f"no-op / python start = {noop / start:.1f}x; no-op - python start = {noop - start:.3f} s; "
          f"target: no-op <= 0.12 s ({'met' if noop <= 0.12 else 'missed'})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
