#!/usr/bin/env python3
"""``roc frame echo map laser --once`` on a live tf tree (tests/nodes/tf_node.py: map->odom static,
odom->base_link at 20 Hz, base_link->laser static), median wall times of runs interleaved:

- roc with its daemon warm;
- roc with no daemon running (the command starts it, so the run pays for its start-up);
- roc ``--no-daemon`` (a fresh participant in the roc process);
- a fresh minimal rclpy process doing the same lookup: it subscribes to /tf and /tf_static and exits
  as soon as it has heard every link between the two frames (the least any fresh tf tool, such as
  tf2_echo, must do; tf2_ros is not on PyPI, so tf2_echo itself cannot run here).

    python bench/frame_bench.py [--runs 5]

tf2_msgs is built by roc from the example workspace into bench/.work/frame-ws (once; then up to date).
ROS domain 92, localhost discovery, roc's daemon in a private runtime directory.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
ROC = str(Path(sys.executable).parent / "roc")
LOOKUP = """
import sys, rclpy
from rclpy.qos import DurabilityPolicy, QoSProfile
from tf2_msgs.msg import TFMessage
source, target = sys.argv[1:3]
rclpy.init()
node = rclpy.create_node("lookup")
parents = {}
def heard(message):
    for t in message.transforms:
        parents[t.child_frame_id] = t.header.frame_id
def chain(frame):
    frames = [frame]
    while frames[-1] in parents:
        frames.append(parents[frames[-1]])
    return frames
node.create_subscription(TFMessage, "/tf", heard, 100)
node.create_subscription(TFMessage, "/tf_static", heard, QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL))
while not set(chain(source)) & set(chain(target)):
    rclpy.spin_once(node, timeout_sec=0.1)
print(chain(source), chain(target))
"""


def sourced_env(runtime: Path) -> dict[str, str]:
    """tf2_msgs built by roc and sourced, in domain 92 with a private roc daemon."""
    workspace = REPO / "bench" / ".work" / "frame-ws"
    shutil.copytree(REPO / "workspaces" / "example" / "src" / "tf2_msgs", workspace / "src" / "tf2_msgs",
                    dirs_exist_ok=True)
    subprocess.run([ROC, "work", "build"], cwd=workspace, check=True, capture_output=True)
    env = dict(os.environ, ROS_DOMAIN_ID="92", ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", XDG_RUNTIME_DIR=str(runtime))
    dumped = subprocess.run(["bash", "-c", f'source "{workspace}/install/setup.bash" && env -0'], env=env,
                            capture_output=True, check=True)
    return dict(item.split("=", 1) for item in dumped.stdout.decode().split("\0") if "=" in item)


def timed(command: list[str], env: dict[str, str]) -> float:
    start = time.perf_counter()
    done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=120)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(command)} failed: {done.stderr.strip()}")
    return time.perf_counter() - start


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="roc-frame-bench-") as runtime:
        return measure(Path(runtime), args.runs)


def measure(runtime: Path, runs: int) -> int:
    """The cases' median times, roc's daemon in ``runtime``."""
    env = sourced_env(runtime)
    echo = [ROC, "frame", "echo", "map", "laser", "--once"]
    stop = [ROC, "daemon", "stop"]
    cases = {
        "roc, daemon warm": lambda: timed(echo, env),
        "roc, daemon not running": lambda: (subprocess.run(stop, env=env, capture_output=True), timed(echo, env))[1],
        "roc --no-daemon": lambda: timed([*echo, "--no-daemon"], env),
        "fresh rclpy process": lambda: timed([sys.executable, "-c", LOOKUP, "map", "laser"], env),
    }
    tree = subprocess.Popen([sys.executable, str(REPO / "tests" / "nodes" / "tf_node.py"), "publish"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        assert tree.stdout.readline().strip() == "ready"
        timed(echo, env)  # the daemon started and discovered
        times: dict[str, list[float]] = {name: [] for name in cases}
        for _ in range(runs):
            for name, case in cases.items():
                times[name].append(case())
            time.sleep(2)  # the daemon started by the last case has discovered the graph
        reference = statistics.median(times["fresh rclpy process"])
        print(f"frame echo map laser --once, median of {runs} runs:")
        for name, values in times.items():
            median = statistics.median(values)
            print(f"  {name:26} {median:6.3f} s   {median / reference:5.2f} x the fresh rclpy process")
    finally:
        tree.terminate()
        tree.wait(timeout=10)
        subprocess.run(stop, env=env, capture_output=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
