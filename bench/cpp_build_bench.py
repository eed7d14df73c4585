#!/usr/bin/env python3
"""C++ build speed, roc against colcon, on the real C++ stack (rclcpp, rclcpp_components, the demos'
and examples' C++ nodes: requirements/cpp-stack.txt), side by side in one run.

    bash scripts/setup.sh --with-cpp      # once: unpacks the sources (and builds the stack for the tests)
    .venv/bin/python bench/cpp_build_bench.py [--runs 1] [--phases cold noop edit ccache cluster]

Each tool builds its own copy of ``.cpp-stack/stack/src`` (``bench/.work/cpp/<tool>``) on the same
underlay (the stack's console_bridge, the venv's wheels), with the same CMake arguments (Release, tests
off, ``--cmake-args`` as scripts/setup_cpp.sh gives them) and the same parallelism (``--parallel-workers
2``; colcon runs make with -j2 in each package, roc shares one jobserver of 2 across packages). Each
figure is the median of ``--runs``; the machine's load average is printed before each build, since it is
shared. Phases, with their goals on a quiet machine:

- ``cold``: from nothing (build/, install/, log/ removed): roc <= 0.75x colcon;
- ``noop``: nothing changed: roc <= 0.2 s (colcon 7-9 s);
- ``edit``: one rclcpp source file edited (an error message in ``node.cpp``: its library's code changes,
  its interface does not): roc <= 0.6x colcon;
- ``ccache``: roc with ``--compiler-cache ccache``, a clean build after one that filled the cache:
  <= 0.1x of roc's cold build;
- ``cluster``: roc on a Dask cluster of 2 workers, one core each, against 1 worker: <= 0.6x.

After the cold builds, the files that only one tool's install tree has are listed. ``--reuse`` keeps
the copies an earlier run built and skips the cold phase.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import time
import uuid
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE.parent / "tests"))
sys.path.insert(0, str(HERE))

from cluster_sim import critical_path, from_workspace  # noqa: E402
from helpers.cluster import start_scheduler, start_worker, stop_all, wait_for_workers  # noqa: E402
from helpers.remote_servers import webdav  # noqa: E402

BIN = Path(sys.executable).parent
STACK = REPO / ".cpp-stack"
WORK = HERE / ".work" / "cpp"
RELEASE = ["--cmake-args", "-DCMAKE_BUILD_TYPE=Release", "-DBUILD_TESTING=OFF"]
OVERRIDE = ["--allow-overriding", "composition_interfaces"]
EDITED = Path("rclcpp-28.1.6", "rclcpp", "src", "rclcpp", "node.cpp")
PHASES = ("cold", "noop", "edit", "ccache", "cluster")
CORES = len(os.sched_getaffinity(0))


def environment() -> dict[str, str]:
    """The environment of a shell with the stack's underlay (console_bridge, then the wheels) sourced."""
    base = {k: v for k, v in os.environ.items() if k not in ("AMENT_PREFIX_PATH", "COLCON_PREFIX_PATH",
                                                             "CMAKE_PREFIX_PATH")}
    base["PATH"] = f"{BIN}{os.pathsep}{base.get('PATH', '')}"
    setup = STACK / "underlay" / "install" / "setup.bash"
    result = subprocess.run(["bash", "-c", 'source "$1" && env -0', "_", str(setup)], env=base,
                            capture_output=True, check=True)
    return dict(item.split("=", 1) for item in result.stdout.decode().split("\0") if "=" in item)


def commands(tool: str) -> list[str]:
    if tool == "roc":
        return [str(BIN / "roc"), "work", "build", "--parallel-workers", "2", *OVERRIDE, *RELEASE]
    # colcon without colcon-override-check (the oracle's set) overrides the venv's package without asking
    return [str(BIN / "colcon"), "build", "--parallel-workers", "2", *RELEASE]


def load() -> str:
    one, five, _ = os.getloadavg()
    return f"load {one:.1f}/{five:.1f}"


def fresh(name: str) -> Path:
    ws = WORK / name
    if ws.exists():
        shutil.rmtree(ws)
    shutil.copytree(STACK / "stack" / "src", ws / "src", symlinks=True)
    return ws


def clean(ws: Path) -> None:
    for folder in ("build", "install", "log"):
        shutil.rmtree(ws / folder, ignore_errors=True)


def timed(ws: Path, command: list[str], env: dict[str, str], label: str) -> float:
    print(f"  {label:<28} {load()} ...", end="", flush=True)
    before = _children_cpu()
    start = time.perf_counter()
    result = subprocess.run(command, cwd=ws, env={**env, "MAKEFLAGS": env.get("MAKEFLAGS", "-j2")},
                            capture_output=True, text=True)
    elapsed = time.perf_counter() - start
    if result.returncode != 0:
        sys.exit(f"\n{' '.join(command)} failed in {ws}:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
    cpu = _children_cpu() - before
    print(f" {elapsed:8.2f} s, {cpu:7.1f} s of CPU (the floor on {CORES} cores: {cpu / CORES:.1f} s)")
    return elapsed


def _children_cpu() -> float:
    """The CPU time of this process's finished children and their descendants (a build's compilers)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def install_files(ws: Path) -> set[str]:
    install = ws / "install"
    return {str(path.relative_to(install)) for path in install.rglob("*") if not path.is_dir()}


def compare_installs(ours: Path, theirs: Path) -> None:
    """The files of one install tree and not the other, by folder (docs/coming-from-colcon.md explains them)."""
    ours_only, theirs_only = install_files(ours) - install_files(theirs), install_files(theirs) - install_files(ours)
    print(f"\ninstall trees: {len(install_files(ours))} files (roc), {len(install_files(theirs))} (colcon)")
    for label, files in (("only roc's", ours_only), ("only colcon's", theirs_only)):
        for name in sorted(files):
            print(f"  {label}: {name}")


def edit(ws: Path, run: int) -> None:
    """A new error message in node.cpp, different from every earlier run's (--reuse keeps the last)."""
    source = ws / "src" / EDITED
    text, count = re.subn(r'"failed to validate subnode namespace[^"]*"',
                          f'"failed to validate subnode namespace (edit {uuid.uuid4().hex[:8]})"', source.read_text())
    assert count, f"{source}: the edited message is not there"
    source.write_text(text)


def cluster(env: dict[str, str], runs: int) -> dict[str, float]:
    """Cold builds on 1 and 2 fresh workers (worker K on core K), each into a fresh cache folder."""
    base = WORK / "cluster"
    base.mkdir(parents=True, exist_ok=True)
    results: dict[str, list[float]] = {"1 worker": [], "2 workers": []}
    (base / "dav").mkdir(exist_ok=True)
    with webdav(base / "dav") as port:
        scheduler, address = start_scheduler(base / "scheduler", env)
        try:
            for run in range(runs):
                for workers in (1, 2):
                    started = []
                    roots = base / f"roots-{workers}"
                    shutil.rmtree(roots, ignore_errors=True)
                    try:
                        for index in range(workers):
                            (roots / f"worker-{index}").mkdir(parents=True)
                            started.append(start_worker(address, roots / f"worker-{index}", f"worker-{index}",
                                                        env, prefix=("taskset", "-c", str(index))))
                        wait_for_workers(address, {f"worker-{i}" for i in range(workers)}, processes=started)
                        ws = fresh(f"cluster-{workers}")
                        command = [str(BIN / "roc"), "work", "build", "--cluster", address, "--remote-cache",
                                   f"http://127.0.0.1:{port}/{uuid.uuid4().hex}", "--parallel-workers",
                                   str(workers), *OVERRIDE, *RELEASE]
                        label = f"{workers} worker{'s' if workers > 1 else ''}"
                        results[label].append(timed(ws, command, env, f"roc, {label} (run {run + 1})"))
                        here = built_here(ws)
                        if here:  # on the client's cores: the figure would not measure the workers
                            sys.exit(f"cpp_build_bench: {label}: built on the client, not on the cluster: "
                                     + "; ".join(here))
                    finally:
                        stop_all(started)
        finally:
            stop_all([scheduler])
    return {label: statistics.median(times) for label, times in results.items()}


def built_here(ws: Path) -> list[str]:
    """The packages a cluster build built on the client instead, and why (its warnings)."""
    events = [json.loads(line) for line in (ws / "log" / "latest_build" / "events.log").read_text().splitlines()]
    return [f"{e['task']}: {e['message']}" for e in events
            if e["event"] == "TaskWarning" and "not on the cluster" in e.get("message", "")]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=1, help="builds of each kind; each figure is their median")
    parser.add_argument("--phases", nargs="+", choices=PHASES, default=list(PHASES))
    parser.add_argument("--reuse", action="store_true", help="keep the copies an earlier run built (no cold phase)")
    args = parser.parse_args(argv)
    if not (STACK / "stack" / "src").is_dir() or not (STACK / "underlay" / "install").is_dir():
        sys.exit("cpp_build_bench: no C++ stack sources: run bash scripts/setup.sh --with-cpp first")
    env = environment()
    figures: dict[str, dict[str, float]] = {}
    tools = ("roc", "colcon")
    wants = set(args.phases)
    if args.reuse:
        spaces = {tool: WORK / tool for tool in tools}
        if not all((ws / "install").is_dir() for ws in spaces.values()):
            sys.exit(f"cpp_build_bench: --reuse: no earlier build in {WORK}/roc and {WORK}/colcon: run without it")
        wants.discard("cold")
    else:  # fresh copies only for the phases that use them (a ccache or cluster run keeps the last ones)
        spaces = {tool: fresh(tool) for tool in tools} if wants & {"cold", "noop", "edit"} else {}

    def each(kind: str, prepare) -> None:
        times: dict[str, list[float]] = {tool: [] for tool in tools}
        for run in range(args.runs):
            for tool in tools:
                prepare(spaces[tool], run)
                times[tool].append(timed(spaces[tool], commands(tool), env, f"{tool} {kind} (run {run + 1})"))
        figures[kind] = {tool: statistics.median(values) for tool, values in times.items()}

    if wants & {"cold", "noop", "edit"} and not args.reuse:
        each("cold", lambda ws, run: clean(ws))
    if "cold" in figures:
        compare_installs(spaces["roc"], spaces["colcon"])
        graph, durations = from_workspace(spaces["roc"])
        print(f"roc's cold build: {len(graph)} packages, {sum(durations.values()):.0f} s of package time summed, "
              f"critical path {critical_path(graph, durations):.0f} s, wall {figures['cold']['roc']:.0f} s")
    if wants & {"noop", "edit"}:
        each("noop", lambda ws, run: None)
    if "edit" in wants:
        each("edit", edit)
    if "ccache" in wants:
        if shutil.which("ccache") is None:
            sys.exit("cpp_build_bench: the ccache phase needs ccache (ROC_SETUP_TEST_TOOLS=1 bash scripts/setup.sh)")
        ws = fresh("ccache")
        cache = ["--compiler-cache", "ccache", "--compiler-cache-dir", str(WORK / "ccache-dir")]
        shutil.rmtree(WORK / "ccache-dir", ignore_errors=True)
        command = [*commands("roc"), *cache]
        fill = timed(ws, command, env, "roc ccache, filling")
        times = []
        for run in range(args.runs):
            clean(ws)
            times.append(timed(ws, command, env, f"roc ccache, clean build (run {run + 1})"))
        figures["ccache"] = {"fill": fill, "clean": statistics.median(times)}
    if "cluster" in wants:
        if shutil.which("taskset") is None:
            sys.exit("cpp_build_bench: the cluster phase needs taskset (util-linux)")
        figures["cluster"] = cluster(env, args.runs)

    print("\nmedians (s):")
    for kind, values in figures.items():
        print(f"  {kind:<8} " + ", ".join(f"{name} {value:.2f}" for name, value in values.items()))
    for kind in ("cold", "edit"):
        if kind in figures:
            print(f"{kind}: roc/colcon {figures[kind]['roc'] / figures[kind]['colcon']:.2f}x")
    if "noop" in figures:
        print(f"noop: roc {figures['noop']['roc']:.2f} s, colcon {figures['noop']['colcon']:.2f} s")
    if "ccache" in figures:  # the filling build is a cold build through ccache (every compile a miss)
        print(f"ccache: clean build / the filling build {figures['ccache']['clean'] / figures['ccache']['fill']:.2f}x")
    if "ccache" in figures and "cold" in figures:
        print(f"ccache: clean build / roc's cold build {figures['ccache']['clean'] / figures['cold']['roc']:.2f}x")
    if "cluster" in figures:
        print(f"cluster: 2 workers / 1 worker {figures['cluster']['2 workers'] / figures['cluster']['1 worker']:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
