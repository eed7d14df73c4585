#!/usr/bin/env python3
"""roc against the real ros2 CLI on one live graph: warm (daemon running) and daemon-less times of
``topic list``, ``topic info -v``, ``node list`` and ``param get``; daemon-less completeness; and the first
query of a session (no daemon running: each tool starts its own) with its completeness.

    python bench/graph_bench.py [--runs 10] [--no-daemon-runs 3] [--completeness-runs 20]
                                [--cold-runs 20] [--range LOCALHOST] [--only cold]
                                [--middlewares fastdds,cyclonedds,mixed,cyclonedds-beside-fastdds]

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

Middlewares (``--middlewares fastdds,cyclonedds,mixed``, default fastdds): each set-up in turn on a
graph of its own, then a summary that puts them side by side.
- ``fastdds``: the graph, roc and ros2 on the wheels' Fast DDS.
- ``cyclonedds``: the graph's nodes, roc and ros2 on rmw_cyclonedds (``bash scripts/setup.sh
  --with-cyclonedds`` builds it in .rmw-stack/), each process as tests/helpers/rmw.py's ``on_middleware``
  gives it: RMW_IMPLEMENTATION=rmw_cyclonedds_cpp and rmw_cyclonedds' prefix first on AMENT_PREFIX_PATH,
  which roc needs and no more (it loads the library itself: roc/middleware.py). The wheels' librcl links
  Fast DDS directly, so every other process of the wheels also needs the library preloaded: the graph's
  nodes and ros2 get ``LD_PRELOAD=.../lib/librmw_cyclonedds_cpp.so`` (roc.middleware.process_environment,
  as roc run does), and with it LD_LIBRARY_PATH naming the wheels' libraries (the venv's lib/ and
  site-packages/ros_*.libs, which the "warm" environment sets anyway, as sourcing the rmw workspace's
  setup script does): the preloaded library needs librmw_dds_common.so and the others before the
  wheels' bootstrapper would set that path, and without it Python does not start (exit 127).
- ``mixed``: the graph, roc and ros2 on Fast DDS, and beside them one Cyclone DDS process on the same
  domain (a talker on /chatter). Target: its cold first query no slower than fastdds's.
- ``cyclonedds-beside-fastdds``: the graph on Fast DDS, roc and ros2 on Cyclone DDS. Target: its cold
  first query no slower than cyclonedds's (the summary's ``cyclonedds-beside-fastdds/cyclonedds``).
Targets: on Cyclone, cold roc at most ros2's cold time on Cyclone and complete N of N; warm roc verbs at
most 1.1x the same verbs on Fast DDS (the summary's ``roc cyclonedds/fastdds``).
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
from helpers.rmw import CYCLONEDDS, FASTRTPS, MISSING, STACK, on_middleware  # noqa: E402

from roc.middleware import process_environment  # noqa: E402

COMMANDS = [("topic", "list"), ("topic", "info", "-v", "/chatter"), ("node", "list"),
            ("param", "get", "/motor_controller", "max_speed")]
COLD_COMMANDS = [("node", "list"), ("topic", "list"), ("service", "list")]
NODES = ["/fibonacci_server", "/listener", "/map_server", "/motor_controller", "/robot1/odom_pub", "/talker"]
# the set-ups of --middlewares: the middleware of the graph's nodes, that of both tools, and the nodes of
# Cyclone DDS processes beside them; and the set-up each is measured against in the summary
CYCLONE_TALKER = [{"name": "cyclone_talker", "publishers": [{"topic": "chatter", "type": "std_msgs/msg/String"}]}]
SETUPS = {"fastdds": (FASTRTPS, FASTRTPS, []), "cyclonedds": (CYCLONEDDS, CYCLONEDDS, []),
          "mixed": (FASTRTPS, FASTRTPS, [CYCLONE_TALKER]), "cyclonedds-beside-fastdds": (FASTRTPS, CYCLONEDDS, [])}
AGAINST = {"cyclonedds-beside-fastdds": "cyclonedds"}  # the others: against fastdds


def booted(env: dict[str, str], venv: Path) -> dict[str, str]:
    """``env`` as in an activated ROS environment: the wheels' bootstrapper does not re-execute Python."""
    site = venv / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / "site-packages"
    libs = [str(venv / "lib")] + sorted(str(p.resolve()) for p in site.glob("ros_*.libs"))
    return {**env, "_ROS_WHEELS_BOOTSTRAP_COMPLETE": "1", "LD_LIBRARY_PATH": os.pathsep.join(libs)}


def tool_env(env: dict[str, str], boot: bool) -> dict[str, str]:
    """Booted with this venv's libraries (the oracle's venv holds the same wheels), or plain (a preloaded
    middleware keeps the libraries: it needs them before the bootstrapper sets them)."""
    if boot:
        return booted(env, Path(sys.prefix))
    plain = {k: v for k, v in env.items() if k not in ("_ROS_WHEELS_BOOTSTRAP_COMPLETE", "LD_LIBRARY_PATH")}
    if env.get("LD_PRELOAD"):
        plain["LD_LIBRARY_PATH"] = booted(env, Path(sys.prefix))["LD_LIBRARY_PATH"]
    return plain


def tool(name: str) -> str:
    return str(BIN / "roc") if name == "roc" else str(ORACLE_VENV / "bin" / "ros2")


def tool_process_env(name: str, env: dict[str, str]) -> dict[str, str]:
    """``env`` for a run of ``name``: roc loads RMW_IMPLEMENTATION's middleware itself; ros2, a program of
    the wheels like any other, gets it preloaded where their librcl links another (docs/middlewares.md)."""
    return env if name == "roc" else process_environment(env)


RUN_BOUND_SECONDS = 60  # a run still going then is stopped and counted as failed, at this time


def timed(name: str, args: tuple[str, ...], env: dict[str, str], boot: bool = True) -> tuple[float, str, int]:
    """Seconds, stdout and exit code of one run of a tool; a run that hangs (`ros2 service list
    --no-daemon` did once, on the subnet range) is stopped after RUN_BOUND_SECONDS and counts as a
    failed run of that time."""
    start = time.perf_counter()
    try:
        done = subprocess.run([tool(name), *args], env=tool_env(tool_process_env(name, env), boot),
                              capture_output=True, text=True, timeout=RUN_BOUND_SECONDS)
    except subprocess.TimeoutExpired:
        print(f"{name} {' '.join(args)}: still running after {RUN_BOUND_SECONDS} s; stopped", file=sys.stderr)
        return float(RUN_BOUND_SECONDS), "", -1
    return time.perf_counter() - start, done.stdout, done.returncode


@contextlib.contextmanager
def live_graph(domain: int, specs: list, discovery_range: str = "LOCALHOST", middleware: str = FASTRTPS,
               cyclone_specs: list = (), tools_middleware: str | None = None):
    """The ros2 oracle installed, the nodes of ``specs`` running in ROS domain ``domain`` with this
    discovery range on ``middleware`` (those of ``cyclone_specs`` on Cyclone DDS), both tools' daemons
    started and given a discovery period; everything stopped afterwards. Yields the tools' environment
    (on ``tools_middleware``, by default ``middleware``) and a fresh work directory."""
    reason = install_oracle()
    if reason:
        raise SystemExit(f"the ros2 CLI is not available: {reason}")
    if (CYCLONEDDS in (middleware, tools_middleware) or cyclone_specs) and not (STACK / "ready").is_file():
        raise SystemExit(MISSING)
    with tempfile.TemporaryDirectory(prefix="roc-bench-") as directory:
        work = Path(directory)
        env = graph_env(0, work)  # then its own domain, outside the tests
        env["ROS_DOMAIN_ID"] = str(domain)
        env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = discovery_range
        processes = []
        try:
            processes += start_nodes(specs, on_middleware(env, middleware))
            processes += start_nodes(list(cyclone_specs), on_middleware(env, CYCLONEDDS))
            env = on_middleware(env, tools_middleware or middleware)
            for name in ("roc", "ros2"):
                subprocess.run([tool(name), "daemon", "start"], env=tool_process_env(name, env), capture_output=True,
                               timeout=60)
            time.sleep(4)
            yield env, work
        finally:
            stop_daemons(env)
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
        subprocess.run([tool(name), "daemon", "stop"], env=tool_env(tool_process_env(name, env), True),
                       capture_output=True, timeout=60)


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


def run_setup(setup: str, options: argparse.Namespace) -> dict[str, list[tuple]]:
    """The warm and no-daemon rows, the completeness counts and the cold rows of one set-up of SETUPS,
    printed as they come."""
    middleware, tools_middleware, cyclone_specs = SETUPS[setup]
    results: dict[str, list[tuple]] = {"warm": [], "complete": [], "cold": []}
    nodes = sorted([*NODES, *(f"/{node['name']}" for spec in cyclone_specs for node in spec)])
    with live_graph(90, DEMO_GRAPH, options.range, middleware, cyclone_specs, tools_middleware) as (env, _):
        for name in ("roc", "ros2"):  # warm-up
            timed(name, ("topic", "list"), env)
        print(f"\nmiddlewares {setup}, discovery range {options.range}")
        if options.only != "cold":
            print(f"{'command':50} {'roc s':>7} {'ros2 s':>7} {'roc/ros2':>8}  failed runs roc, ros2")
            modes = (("warm", (), options.runs, True), ("no daemon", ("--no-daemon",), options.no_daemon_runs, True))
            for label, extra, runs, boot in modes:
                for command, roc_time, ros2_time, roc_failed, ros2_failed in compare(env, runs, extra, boot):
                    results["warm"].append((f"{command} ({label})", roc_time, ros2_time))
                    print(f"{command + ' (' + label + ')':50} {roc_time:7.3f} {ros2_time:7.3f} "
                          f"{roc_time / ros2_time:8.2f}  {roc_failed}, {ros2_failed}")
            for name in ("roc", "ros2"):
                complete = 0
                for _ in range(options.completeness_runs):
                    _, out, _ = timed(name, ("node", "list", "--no-daemon"), env)
                    complete += out.splitlines() == nodes
                results["complete"].append((name, complete))
                print(f"{name} node list --no-daemon complete in {complete} of {options.completeness_runs} runs")
        if options.only != "warm":
            print(f"{'first query (no daemon running)':50} {'roc s':>7} {'ros2 s':>7} {'roc/ros2':>8}  "
                  f"complete runs roc, ros2 (of {options.cold_runs})")
            for label, extra in (("cold", ()), ("cold, --no-daemon", ("--no-daemon",))):
                for command, roc_time, ros2_time, roc_complete, ros2_complete in cold(env, options.cold_runs, extra):
                    results["cold"].append((f"{command} ({label})", roc_time, ros2_time, roc_complete, ros2_complete))
                    print(f"{command + ' (' + label + ')':50} {roc_time:7.3f} {ros2_time:7.3f} "
                          f"{roc_time / ros2_time:8.2f}  {roc_complete}, {ros2_complete}")
    return results


def summary(results: dict[str, dict[str, list[tuple]]]) -> None:
    """The set-ups side by side: per command, roc's and ros2's medians on each, and roc's time on each
    against its time on fastdds (cyclonedds/fastdds: the warm target; mixed/fastdds: the cold one), or on
    the set-up AGAINST names (cyclonedds-beside-fastdds/cyclonedds: the cold target)."""
    setups = list(results)
    for part, title in (("warm", "warm and no daemon"), ("cold", "first query (no daemon running)")):
        rows = {setup: {row[0]: row for row in results[setup][part]} for setup in setups}
        commands = [row[0] for row in results[setups[0]][part]]
        if not commands:
            continue
        print(f"\n{title}: roc s / ros2 s (roc/ros2" + (", complete roc, ros2" if part == "cold" else "")
              + ") per set-up" + ("; roc against roc on fastdds" if "fastdds" in setups and len(setups) > 1 else ""))
        for command in commands:
            cells = []
            for setup in setups:
                row = rows[setup].get(command)
                if row is None:
                    continue
                cell = f"{setup} {row[1]:.3f}/{row[2]:.3f} ({row[1] / row[2]:.2f}"
                cells.append(cell + (f", {row[3]}, {row[4]})" if part == "cold" else ")"))
                against = AGAINST.get(setup, "fastdds")
                if setup != against and command in rows.get(against, {}):
                    cells[-1] += f" {setup}/{against} {row[1] / rows[against][command][1]:.2f}"
            print(f"  {command:42} " + "  ".join(cells))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--no-daemon-runs", type=int, default=3)
    parser.add_argument("--completeness-runs", type=int, default=20)
    parser.add_argument("--cold-runs", type=int, default=20)
    parser.add_argument("--range", choices=("LOCALHOST", "SUBNET"), default="LOCALHOST")
    parser.add_argument("--only", choices=("warm", "cold"), help="run only the warm (and no daemon) or cold part")
    parser.add_argument("--middlewares", default="fastdds",
                        help=f"comma-separated set-ups, run in turn and summed up side by side: {', '.join(SETUPS)}")
    options = parser.parse_args()
    setups = options.middlewares.split(",")
    unknown = [setup for setup in setups if setup not in SETUPS]
    if unknown:
        parser.error(f"--middlewares: unknown set-up {', '.join(unknown)} (choose from {', '.join(SETUPS)})")
    results = {setup: run_setup(setup, options) for setup in setups}
    if len(setups) > 1:
        summary(results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
