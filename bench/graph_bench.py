#!/usr/bin/env python3
"""roc against the real ros2 CLI on one live graph: warm (daemon running) and daemon-less times of
``topic list``, ``topic info -v``, ``node list`` and ``param get``; daemon-less completeness; and the first
query of a session (no daemon running: each tool starts its own) with its completeness.

    python bench/graph_bench.py [--runs 10] [--no-daemon-runs 3] [--completeness-runs 20]
                                [--cold-runs 20] [--range LOCALHOST] [--only cold]

The graph is the demo graph of the tests (tests/helpers/graph.py: six nodes in three processes) in
ROS domain 90 with localhost discovery; roc's daemon gets a private runtime directory. The ros2 CLI
is the oracle of the tests (installed into ~/.cache/roc-tests/ros2cli-venv when missing). Runs of
the two tools are interleaved; the table shows median wall times and the ratio roc/ros2. "warm" runs
as in an activated ROS environment (the wheels' bootstrapper does not re-execute Python: the
bootstrap flag and the wheels' LD_LIBRARY_PATH are set); "plain env" without them, so every Python
start of either tool re-executes itself once.
Completeness: ``node list --no-daemon`` run N times by each tool, counted complete when it lists all
six nodes. Targets: warm roc at most 1/4 of ros2's warm time; daemon-less complete N of N.
Cold: before each run both tools' daemons are stopped, then ``node list``, ``topic list`` and
``service list`` (each against its warm answer: complete or not), with and without ``--no-daemon``.
Target: cold roc at most ros2's cold time, complete N of N. ``--range SUBNET`` runs the graph and both
tools with the default discovery range instead of the tests' LOCALHOST.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from helpers.graph import (  # noqa: E402
    BIN,
    DEMO_GRAPH,
    ORACLE_VENV,
    graph_env,
    install_oracle,
    start_nodes,
    stop_all,
    stop_daemon,
)

COMMANDS = [("topic", "list"), ("topic", "info", "-v", "/chatter"), ("node", "list"),
            ("param", "get", "/motor_controller", "max_speed")]
COLD_COMMANDS = [("node", "list"), ("topic", "list"), ("service", "list")]
NODES = ["/fibonacci_server", "/listener", "/map_server", "/motor_controller", "/robot1/odom_pub", "/talker"]


def booted(env: dict[str, str], venv: Path) -> dict[str, str]:
    """``env`` as in an activated ROS environment: the wheels' bootstrapper does not re-execute Python."""
    site = venv / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / "site-packages"
    libs = [str(venv / "lib")] + sorted(str(p.resolve()) for p in site.glob("ros_*.libs"))
    return {**env, "_ROS_WHEELS_BOOTSTRAP_COMPLETE": "1", "LD_LIBRARY_PATH": os.pathsep.join(libs)}


def tool_env(env: dict[str, str], boot: bool) -> dict[str, str]:
    """Booted with this venv's libraries (the oracle's venv holds the same wheels), or plain."""
    if boot:
        return booted(env, Path(sys.prefix))
    return {k: v for k, v in env.items() if k not in ("_ROS_WHEELS_BOOTSTRAP_COMPLETE", "LD_LIBRARY_PATH")}


def tool(name: str) -> str:
    return str(BIN / "roc") if name == "roc" else str(ORACLE_VENV / "bin" / "ros2")


RUN_BOUND_SECONDS = 60  # a run still going then is stopped and counted as failed, at this time


def timed(name: str, args: tuple[str, ...], env: dict[str, str], boot: bool = True) -> tuple[float, str, int]:
    """Seconds, stdout and exit code of one run of a tool; a run that hangs (`ros2 service list
    --no-daemon` did once, on the subnet range) is stopped after RUN_BOUND_SECONDS and counts as a
    failed run of that time."""
    start = time.perf_counter()
    try:
        done = subprocess.run([tool(name), *args], env=tool_env(env, boot), capture_output=True, text=True,
                              timeout=RUN_BOUND_SECONDS)
    except subprocess.TimeoutExpired:
        print(f"{name} {' '.join(args)}: still running after {RUN_BOUND_SECONDS} s; stopped", file=sys.stderr)
        return float(RUN_BOUND_SECONDS), "", -1
    return time.perf_counter() - start, done.stdout, done.returncode


@contextlib.contextmanager
def live_graph(domain: int, specs: list, discovery_range: str = "LOCALHOST"):
    """The ros2 oracle installed, the nodes of ``specs`` running in ROS domain ``domain`` with this
    discovery range, both tools' daemons started and given a discovery period; everything stopped
    afterwards. Yields the environment and a fresh work directory."""
    reason = install_oracle()
    if reason:
        raise SystemExit(f"the ros2 CLI is not available: {reason}")
    with tempfile.TemporaryDirectory(prefix="roc-bench-") as directory:
        work = Path(directory)
        env = graph_env(0, work)  # then its own domain, outside the tests
        env["ROS_DOMAIN_ID"] = str(domain)
        env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = discovery_range
        processes = start_nodes(specs, env)
        try:
            for name in ("roc", "ros2"):
                subprocess.run([tool(name), "daemon", "start"], env=env, capture_output=True, timeout=60)
            time.sleep(4)
            yield env, work
        finally:
            stop_daemon(env)
            stop_all(processes)


def compare(env: dict[str, str], runs: int, extra: tuple[str, ...], boot: bool) -> list[tuple]:
    """(command, roc median, ros2 median, failed runs of roc, of ros2) per command."""
    rows = []
    for command in COMMANDS:
        times: dict[str, list[float]] = {"roc": [], "ros2": []}
        failed = {"roc": 0, "ros2": 0}
        for _ in range(runs):
            for name in ("roc", "ros2"):
                elapsed, _, code = timed(name, command + extra, env, boot)
                times[name].append(elapsed)
                failed[name] += code != 0
        rows.append((" ".join(command), statistics.median(times["roc"]), statistics.median(times["ros2"]),
                     failed["roc"], failed["ros2"]))
    return rows


def stop_daemons(env: dict[str, str]) -> None:
    for name in ("roc", "ros2"):
        subprocess.run([tool(name), "daemon", "stop"], env=tool_env(env, True), capture_output=True, timeout=60)


def cold(env: dict[str, str], runs: int, extra: tuple[str, ...]) -> list[tuple]:
    """(command, roc median, ros2 median, roc complete runs, ros2 complete runs) per command, each run
    after both daemons were stopped; complete = the warm daemon's answer."""
    rows = []
    for command in COLD_COMMANDS:
        expected = timed("roc", command, env)[1]
        times: dict[str, list[float]] = {"roc": [], "ros2": []}
        complete = {"roc": 0, "ros2": 0}
        for _ in range(runs):
            for name in ("roc", "ros2"):
                stop_daemons(env)
                elapsed, out, _ = timed(name, command + extra, env)
                times[name].append(elapsed)
                complete[name] += out == expected
                if name == "roc" and out != expected:  # say what roc missed (or added), to find out why
                    missed = sorted(set(expected.splitlines()) - set(out.splitlines()))
                    added = sorted(set(out.splitlines()) - set(expected.splitlines()))
                    print(f"roc {' '.join(command + extra)}: missed {missed}, added {added}", file=sys.stderr)
        subprocess.run([tool("roc"), "daemon", "start"], env=env, capture_output=True, timeout=60)
        rows.append((" ".join(command), statistics.median(times["roc"]), statistics.median(times["ros2"]),
                     complete["roc"], complete["ros2"]))
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--no-daemon-runs", type=int, default=3)
    parser.add_argument("--completeness-runs", type=int, default=20)
    parser.add_argument("--cold-runs", type=int, default=20)
    parser.add_argument("--range", choices=("LOCALHOST", "SUBNET"), default="LOCALHOST")
    parser.add_argument("--only", choices=("warm", "cold"), help="run only the warm (and no daemon) or cold part")
    options = parser.parse_args()
    with live_graph(90, DEMO_GRAPH, options.range) as (env, _):
        for name in ("roc", "ros2"):  # warm-up
            timed(name, ("topic", "list"), env)
        print(f"discovery range {options.range}")
        if options.only != "cold":
            print(f"{'command':50} {'roc s':>7} {'ros2 s':>7} {'roc/ros2':>8}  failed runs roc, ros2")
            modes = (("warm", (), options.runs, True), ("no daemon", ("--no-daemon",), options.no_daemon_runs, True))
            for label, extra, runs, boot in modes:
                for command, roc_time, ros2_time, roc_failed, ros2_failed in compare(env, runs, extra, boot):
                    print(f"{command + ' (' + label + ')':50} {roc_time:7.3f} {ros2_time:7.3f} "
                          f"{roc_time / ros2_time:8.2f}  {roc_failed}, {ros2_failed}")
            for name in ("roc", "ros2"):
                complete = 0
                for _ in range(options.completeness_runs):
                    _, out, _ = timed(name, ("node", "list", "--no-daemon"), env)
                    complete += out.splitlines() == NODES
                print(f"{name} node list --no-daemon complete in {complete} of {options.completeness_runs} runs")
        if options.only != "warm":
            print(f"{'first query (no daemon running)':50} {'roc s':>7} {'ros2 s':>7} {'roc/ros2':>8}  "
                  f"complete runs roc, ros2 (of {options.cold_runs})")
            for label, extra in (("cold", ()), ("cold, --no-daemon", ("--no-daemon",))):
                for command, roc_time, ros2_time, roc_complete, ros2_complete in cold(env, options.cold_runs, extra):
                    print(f"{command + ' (' + label + ')':50} {roc_time:7.3f} {ros2_time:7.3f} "
                          f"{roc_time / ros2_time:8.2f}  {roc_complete}, {ros2_complete}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
