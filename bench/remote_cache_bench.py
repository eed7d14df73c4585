#!/usr/bin/env python3
"""The remote build cache on a synthetic workspace, side by side with colcon and roc's cold builds.

    .venv/bin/python bench/remote_cache_bench.py [--packages 100] [--workers 2] [--skip-colcon]

One WebDAV server (wsgidav, as in the tests) on localhost, files in ``bench/.work/remote/dav``. Each
step works in a fresh copy of ``bench/.work/ws<N>`` (gen_workspace.py), all with ``--parallel-workers``:

1. ``colcon``: colcon's cold build;
2. ``roc cold``: roc's cold build, no cache;
3. ``ci``: roc's cold build in read-write mode with ``--compiler-cache sccache`` (fills both caches);
4. ``dev``: a fresh checkout at another path, built from the warm remote cache (read mode): every
   package must be restored (goals: <= 0.1x colcon's cold build, <= 0.2x roc's);
5. ``leaf edit``: in ``dev``, a function added to one C++ source of a package nothing depends on:
   exactly one package must be built (that source's compile misses sccache, its other one hits);
6. ``compiler``: another fresh checkout built with ``--force`` (no package restored) and sccache on
   the same server (read mode): every package is built, and its compiles hit (sccache's hit rate).

Prints one line per step (wall time, packages built/restored, sccache's statistics line) and the
ratios. Exits 1 when a step fails or a count is wrong; a missed time goal only shows in the verdict.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))

from build_bench import BIN, WORK, environment  # noqa: E402
from gen_workspace import ensure, plan  # noqa: E402
from helpers.remote_servers import webdav  # noqa: E402

BASE = WORK / "remote"


def copy(source: Path, destination: Path) -> Path:
    if destination.exists():
        shutil.rmtree(destination)
    shutil.copytree(source / "src", destination / "src")
    return destination


def run(command: list[str], cwd: Path) -> tuple[float, str]:
    start = time.perf_counter()
    result = subprocess.run(command, cwd=cwd, env=environment(), capture_output=True, text=True)
    elapsed = time.perf_counter() - start
    if result.returncode != 0:
        sys.exit(f"{' '.join(command)} failed in {cwd}:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
    return elapsed, result.stdout


def counts(workspace: Path) -> tuple[int, int]:
    """(built, restored) from roc's event log of the last build."""
    events = [json.loads(line) for line in (workspace / "log" / "latest_build" / "events.log").read_text().splitlines()]
    built = {e["task"] for e in events if e["event"] == "TaskStarted"}
    restored = {e["task"] for e in events if e["event"] == "TaskFinished" and e.get("restored")}
    return len(built), len(restored)


def sccache_line(output: str) -> str:
    return next((line for line in output.splitlines() if line.startswith("sccache: ")), "")


def leaf_source(workspace: Path, packages: int) -> Path:
    """A C++ source of a package no other package depends on."""
    specs = plan(packages)
    used = {d for spec in specs for d in spec.depends}
    for spec in reversed(specs):
        if spec.name not in used and spec.type in ("ros.ament_cmake", "cmake", "ros.cmake"):
            return workspace / "src" / spec.repo / spec.name / "src" / f"{spec.name}.cpp"
    raise SystemExit("no C++ leaf package")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--packages", type=int, default=100)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--skip-colcon", action="store_true", help="no colcon cold build (no colcon ratio)")
    args = parser.parse_args(argv)
    source = WORK / f"ws{args.packages}"
    ensure(source, args.packages)
    if BASE.exists():
        shutil.rmtree(BASE)
    (BASE / "dav").mkdir(parents=True)
    (BASE / "dav" / "team" / "sccache").mkdir(parents=True)  # wsgidav makes no parent folders for sccache
    workers = ["--parallel-workers", str(args.workers)]
    roc = [str(BIN / "roc"), "work", "build", *workers]
    compiler = ["--compiler-cache", "sccache"]  # on the remote cache's server (WebDAV)
    ok = True
    times: dict[str, float] = {}
    print(f"# remote cache, {args.packages} packages, --parallel-workers {args.workers}, load "
          f"{os.getloadavg()[0]:.1f}", flush=True)

    def report(step: str, seconds: float, workspace: Path | None, output: str = "", expect=None) -> None:
        nonlocal ok
        times[step] = seconds
        built, restored = counts(workspace) if workspace else (args.packages, 0)
        line = f"{step:<10}{seconds:>8.1f}s  built {built:>4}  restored {restored:>4}  {sccache_line(output)}"
        if expect and (built, restored) != expect:
            line += f"  WRONG: expected built {expect[0]}, restored {expect[1]}"
            ok = False
        print(line, flush=True)

    with webdav(BASE / "dav") as port:
        url = f"http://127.0.0.1:{port}/team"
        if not args.skip_colcon:
            ws = copy(source, BASE / "colcon")
            seconds, _ = run([str(BIN / "colcon"), "build", *workers], ws)
            report("colcon", seconds, None)
        ws = copy(source, BASE / "roc")
        seconds, output = run(roc, ws)
        report("roc cold", seconds, ws, output, (args.packages, 0))
        ws = copy(source, BASE / "ci")
        seconds, output = run([*roc, "--remote-cache", url, "--remote-cache-mode", "read-write", *compiler], ws)
        report("ci", seconds, ws, output, (args.packages, 0))
        dev = copy(source, BASE / "another path" / "dev")
        seconds, output = run([*roc, "--remote-cache", url, *compiler], dev)
        report("dev", seconds, dev, output, (0, args.packages))
        leaf = leaf_source(dev, args.packages)
        leaf.write_text(leaf.read_text() + "\nint edited_by_the_bench() { return 1; }\n")
        seconds, output = run([*roc, "--remote-cache", url, *compiler], dev)
        report("leaf edit", seconds, dev, output, (1, 0))
        ws = copy(source, BASE / "third place" / "compiler")
        seconds, output = run([*roc, "--force", "--remote-cache", url, *compiler], ws)
        report("compiler", seconds, ws, output, (args.packages, 0))
    dev_time = times["dev"]
    verdicts = [f"dev/roc cold = {dev_time / times['roc cold']:.3f} (goal <= 0.2)",
                f"ci/roc cold = {times['ci'] / times['roc cold']:.2f} (the cost of uploading and sccache)",
                f"compiler/roc cold = {times['compiler'] / times['roc cold']:.2f} (every remote key missed, "
                f"compiles from sccache)"]
    if "colcon" in times:
        verdicts.insert(0, f"dev/colcon cold = {dev_time / times['colcon']:.3f} (goal <= 0.1)")
    print("\n".join(verdicts))
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
