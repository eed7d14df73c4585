#!/usr/bin/env python3
"""Message conversion speed: roc's (roc/ros/messages.py) and rosidl_runtime_py's (what ros2 uses) side by side.

    .venv/bin/python bench/messages_bench.py [--repeat 5]

Messages: a sensor_msgs/PointCloud2 with 1 MiB of data, a 1000x1000 nav_msgs/OccupancyGrid and a
nav_msgs/Odometry. For each: message -> dict, dict -> message (ros2: set_message_fields), and the
YAML text ``topic echo`` prints by default (arrays truncated at 128). rosidl_runtime_py is unpacked
from shared/oracles into bench/.work/; without it only roc's times are printed. Best of --repeat runs.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import tarfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
ORACLE = REPO.parent / "shared" / "oracles" / "rosidl_runtime_py-0.13.1.tar.gz"
WORK = HERE / ".work" / "rosidl_runtime_py"

from roc.ros.messages import fill_message, message_to_dict, message_to_yaml  # noqa: E402


def oracle() -> Any | None:
    if not ORACLE.is_file():
        return None
    if not (WORK / "rosidl_runtime_py").is_dir():
        WORK.parent.mkdir(parents=True, exist_ok=True)
        with tarfile.open(ORACLE) as tar:
            tar.extractall(WORK.parent, filter="data")
    sys.path.insert(0, str(WORK))
    return importlib.import_module("rosidl_runtime_py")


def best(function: Callable[[dict], Any], make_input: Callable[[], dict], repeat: int) -> float:
    """Best time of ``function(input)``, with a fresh input each run (ros2's set_message_fields
    replaces the dicts of message lists in its input by messages)."""
    times = []
    for _ in range(repeat):
        data = make_input()
        start = time.perf_counter()
        function(data)
        times.append(time.perf_counter() - start)
    return min(times)


def samples() -> dict[str, Any]:
    cloud = fill_message("sensor_msgs/msg/PointCloud2", {
        "height": 1, "width": 65536, "point_step": 16, "row_step": 1 << 20,
        "fields": [{"name": n, "offset": 4 * i, "datatype": 7, "count": 1} for i, n in enumerate("xyzi")],
        "data": list(range(256)) * 4096})
    grid = fill_message("nav_msgs/msg/OccupancyGrid", {
        "info": {"resolution": 0.05, "width": 1000, "height": 1000}, "data": [-1, 0, 100, 50] * 250000})
    odom = fill_message("nav_msgs/msg/Odometry", {"header": {"frame_id": "odom"}, "child_frame_id": "base",
                                                  "pose": {"covariance": [0.1] * 36}})
    return {"PointCloud2 (1 MiB)": cloud, "OccupancyGrid (1000x1000)": grid, "Odometry": odom}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    ros = oracle()
    rows = []
    for label, msg in samples().items():
        def make_input(msg: Any = msg) -> dict:
            return message_to_dict(msg)

        cases = [
            ("to dict", lambda _, msg=msg: message_to_dict(msg),
             ros and (lambda _, msg=msg: ros.message_to_ordereddict(msg))),
            ("from dict", lambda data, msg=msg: fill_message(type(msg), data),
             ros and (lambda data, msg=msg: ros.set_message_fields(type(msg)(), data))),
            ("echo YAML", lambda _, msg=msg: message_to_yaml(msg, truncate_length=128),
             ros and (lambda _, msg=msg: ros.message_to_yaml(msg, truncate_length=128))),
        ]
        for what, mine, theirs in cases:
            roc_time = best(mine, make_input, args.repeat)
            ros_time = best(theirs, make_input, args.repeat) if theirs else None
            rows.append((label, what, roc_time, ros_time))
    print(f"{'message':28} {'operation':10} {'roc ms':>9} {'ros2 ms':>9} {'roc/ros2':>9}")
    for label, what, roc_time, ros_time in rows:
        theirs = f"{ros_time * 1e3:9.2f}" if ros_time else f"{'-':>9}"
        ratio = f"{roc_time / ros_time:9.2f}" if ros_time else f"{'-':>9}"
        print(f"{label:28} {what:10} {roc_time * 1e3:9.2f} {theirs} {ratio}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
