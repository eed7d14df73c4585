"""Bytes on the wire with a DDS content filter (``roc topic bw --content-filter``): unfiltered, the
filter evaluated by the middleware (Fast DDS, on the publisher's side), and the same filter evaluated
by roc (ROC_MIDDLEWARE_CONTENT_FILTER=0), in a network namespace of its own, Fast DDS on UDP only, so
the loopback interface carries this graph alone (tests/nodes/content_filter_wire.py, run ROUNDS times).
Needs root (unshare -n).

    .venv/bin/python bench/content_filter_bench.py [ROUNDS] [RATE_HZ] [SIZE_BYTES] [WINDOW_S]"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MODES = ("unfiltered", "middleware", "roc")


def main() -> None:
    given = sys.argv[1:] + ["3", "100", "2000", "3"][len(sys.argv) - 1:]
    rounds, rate, size, window = int(given[0]), given[1], given[2], given[3]
    env = {**os.environ, "ROS_DOMAIN_ID": os.environ.get("ROS_DOMAIN_ID", "91")}
    env.pop("ROS_AUTOMATIC_DISCOVERY_RANGE", None)  # the namespace has only its loopback
    runs = []
    for _ in range(rounds):
        result = subprocess.run(["unshare", "-n", sys.executable, str(ROOT / "tests/nodes/content_filter_wire.py"),
                                 rate, size, window, str(ROOT / ".venv/bin/roc")], env=env, capture_output=True,
                                text=True, timeout=300, check=True)
        runs.append(json.loads(result.stdout))
    wire = {mode: statistics.median(run[mode]["wire_bytes_per_second"] for run in runs) for mode in MODES}
    delivered = {mode: statistics.median(run[mode]["bw"]["bytes_per_second"] for run in runs) for mode in MODES}
    print(f"{rate} Hz of {size} B messages, a filter passing one in ten; medians of {rounds} rounds")
    print("| run | on the wire kB/s | delivered kB/s | wire / unfiltered wire |")
    print("| --- | ---: | ---: | ---: |")
    for mode in MODES:
        print(f"| {mode} | {wire[mode] / 1000:.1f} | {delivered[mode] / 1000:.1f} | "
              f"{wire[mode] / wire['unfiltered']:.2f} |")


if __name__ == "__main__":
    main()
