#!/usr/bin/env python3
"""``roc idl protobuf`` on every .msg of common_interfaces: .msg -> .proto, then .proto -> .msg.

    .venv/bin/python bench/idl_bench.py [--runs 3]

One roc call per direction (every file on one command line), each output checked by roc itself
(protoc for the .proto files, rosidl_adapter for the .msg files). Reports the wall time of each call
(median of the runs, process start included) and how many files it wrote.
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
WORK = HERE / ".work" / "idl"
ROC = Path(sys.executable).parent / "roc"
COMMON_INTERFACES = ("actionlib_msgs", "diagnostic_msgs", "geometry_msgs", "nav_msgs", "sensor_msgs",
                     "shape_msgs", "std_msgs", "stereo_msgs", "trajectory_msgs", "visualization_msgs")


def timed(command: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    runs = parser.parse_args().runs
    share = Path(sys.prefix) / "share"
    sources = sorted(str(f) for package in COMMON_INTERFACES for f in (share / package / "msg").glob("*.msg"))
    if not sources:
        raise SystemExit(f"no common_interfaces .msg files under {share}: run scripts/setup.sh")
    to_proto, to_msg = [], []
    for _ in range(runs):
        shutil.rmtree(WORK, ignore_errors=True)
        to_proto.append(timed([str(ROC), "idl", "protobuf", "-o", str(WORK / "proto"), *sources]))
        protos = sorted(str(f) for f in (WORK / "proto").glob("*/*.proto"))
        to_msg.append(timed([str(ROC), "idl", "protobuf", "-I", str(WORK / "proto"), "-o", str(WORK / "msg"),
                             *protos]))
    written = len(list((WORK / "msg").glob("*/msg/*.msg")))
    print(f"common_interfaces: {len(sources)} .msg files, {runs} runs (median)")
    print(f"  .msg -> .proto  one call: {statistics.median(to_proto):.3f} s  ({len(protos)} files)")
    print(f"  .proto -> .msg  one call: {statistics.median(to_msg):.3f} s  ({written} files)")
    print(f"  round trip               {statistics.median(to_proto) + statistics.median(to_msg):.3f} s")


if __name__ == "__main__":
    main()
