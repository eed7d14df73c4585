#!/usr/bin/env python3
"""Where does ``roc work list -t`` spend its time? Start-up, imports and a cProfile breakdown.

    python bench/profile_list.py [--packages 1000] [--runs 10]

Runs everything from the generated workspace ``bench/.work/wsN`` (made by gen_workspace.py when
missing) in the bootstrapped environment (``_ROS_WHEELS_BOOTSTRAP_COMPLETE=1`` and the wheels'
``LD_LIBRARY_PATH``), so that no process re-executes itself, except where a line says otherwise:

1. process wall times (median of --runs): bare interpreter, interpreter with site/.pth files, the
   bootstrapper re-exec, importing roc's CLI, building the whole parser (``--help``), and the full
   command on an empty directory and on the workspace;
2. ``python -X importtime`` (median self time per module over --runs runs): the costliest modules;
3. ``python -m cProfile`` of the command: time per phase (imports, argparse, crawl, package.xml
   parsing, CMake and Python project reading, topological order, output) and the top functions.
   The full ``-s cumtime`` listing is written to ``bench/.work/list_profile.txt``.

cProfile inflates Python-heavy code (about 1.4x here); read its numbers as shares, not as wall times.
"""

from __future__ import annotations

import argparse
import io
import os
import pstats
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from gen_workspace import ensure  # noqa: E402
from list_bench import environments  # noqa: E402


def median_wall(command: list[str], cwd: Path, env: dict[str, str], runs: int) -> float:
    times = []
    for _ in range(runs + 1):  # the first run warms the caches and is dropped
        start = time.perf_counter()
        subprocess.run(command, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
        times.append(time.perf_counter() - start)
    return statistics.median(times[1:])


def process_times(venv: Path, workspace: Path, envs: dict[str, dict[str, str]], runs: int) -> None:
    python, roc = str(venv / "bin" / "python"), str(venv / "bin" / "roc")
    empty = Path(tempfile.mkdtemp(prefix="roc-empty-"))
    steps = [
        ("python -S -c pass (no site, no .pth)", [python, "-S", "-c", "pass"], empty, "boot"),
        ("python -c pass (site + .pth files)", [python, "-c", "pass"], empty, "boot"),
        ("python -c pass, plain env (bootstrapper re-exec)", [python, "-c", "pass"], empty, "plain"),
        ("python -c 'import roc.cli.main'", [python, "-c", "import roc.cli.main"], empty, "boot"),
        ("roc work list --help (whole parser built)", [roc, "work", "list", "--help"], empty, "boot"),
        ("roc work list -t in an empty directory", [roc, "work", "list", "-t"], empty, "boot"),
        (f"roc work list -t in {workspace.name}", [roc, "work", "list", "-t"], workspace, "boot"),
        (f"roc work list -t in {workspace.name}, plain env", [roc, "work", "list", "-t"], workspace, "plain"),
    ]
    print(f"\n1. process wall times (median of {runs}, ms)")
    for label, command, cwd, variant in steps:
        print(f"  {median_wall(command, cwd, envs[variant], runs) * 1000:7.1f}  {label}")
    os.rmdir(empty)


_IMPORT_LINE = re.compile(r"import time:\s+(\d+) \|\s+(\d+) \|( *)(\S+)")


def import_times(venv: Path, workspace: Path, env: dict[str, str], runs: int) -> None:
    selfs: dict[str, list[int]] = {}
    cumulative: dict[str, list[int]] = {}
    top_levels: list[int] = []
    for _ in range(runs):
        result = subprocess.run([str(venv / "bin" / "python"), "-X", "importtime", "-m", "roc", "work", "list", "-t"],
                                cwd=workspace, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                                check=True)
        total = 0
        for match in _IMPORT_LINE.finditer(result.stderr):
            self_us, cumulative_us, indent, name = int(match[1]), int(match[2]), match[3], match[4]
            selfs.setdefault(name, []).append(self_us)
            cumulative.setdefault(name, []).append(cumulative_us)
            if len(indent) == 1:  # a top-level import: these add up to the whole import time
                total += cumulative_us
        top_levels.append(total)
    med_self = {name: statistics.median(v) for name, v in selfs.items()}
    med_cumulative = {name: statistics.median(v) for name, v in cumulative.items()}
    print(f"\n2. -X importtime (median over {runs} runs; this includes the interpreter's own start-up imports)")
    print(f"  all imports: {statistics.median(top_levels) / 1000:.1f} ms")
    groups: dict[str, float] = {}
    for name, value in med_self.items():
        head = name.split(".")[0]
        key = head if head in ("roc", "lxml", "encodings", "site", "_distutils_hack") or head.startswith("__editable__") \
            else "stdlib and other"
        groups[key] = groups.get(key, 0) + value
    print("  self time by package: " + ", ".join(
        f"{k} {v / 1000:.1f} ms" for k, v in sorted(groups.items(), key=lambda kv: -kv[1])))
    print("  costliest modules by cumulative time (ms):")
    shown = sorted(med_cumulative.items(), key=lambda kv: -kv[1])[:25]
    for name, value in shown:
        print(f"    {value / 1000:6.1f} cumulative {med_self[name] / 1000:6.1f} self  {name}")


# (label, file suffix or None, function name); cumulative times of these functions are the phases.
PHASES = (
    ("imports (all, cumulative)", None, "_find_and_load"),
    ("argparse: build_parser (incl. command imports)", "roc/cli/main.py", "build_parser"),
    ("argparse: parse_args", "argparse.py", "parse_args"),
    ("load_workspace (everything below)", "roc/workspace/load.py", "load_workspace"),
    ("  discover_packages (crawl + identify)", "roc/workspace/discovery.py", "discover_packages"),
    ("    os.walk", "os", "_walk"),
    ("    os.path.realpath", "posixpath", "realpath"),
    ("    os.path.relpath", "posixpath", "relpath"),
    ("    identify (all packages)", "roc/workspace/identify.py", "identify"),
    ("      parse_manifest (package.xml)", "roc/workspace/manifest.py", "parse_manifest"),
    ("        its own time: lxml parsing (Cython, unseen by cProfile)", "roc/workspace/manifest.py", "self:parse_manifest"),
    ("        _ManifestReader.read", "roc/workspace/manifest.py", "read"),
    ("      read_cmake_project", "roc/workspace/cmake_project.py", "read_cmake_project"),
    ("      read_setup_py", "roc/workspace/python_setup.py", "read_setup_py"),
    ("      read_setup_cfg", "roc/workspace/python_setup.py", "read_setup_cfg"),
    ("  topological_order", "roc/workspace/graph.py", "topological_order"),
    ("  select_packages", "roc/workspace/selection.py", "select_packages"),
    ("output: print_lines", "roc/render.py", "print_lines"),
    ("pathlib (all uses)", None, "pathlib"),
)


def _phase_time(stats: dict, suffix: str | None, function: str) -> float | None:
    if function == "pathlib":  # total own time spent inside pathlib
        times = [tt for (file, _, _), (_, _, tt, _, _) in stats.items() if file.endswith("pathlib.py")]
        return sum(times) if times else None
    own = function.startswith("self:")
    function = function.removeprefix("self:")
    found = None
    for (file, _, name), (_, _, tt, ct, _) in stats.items():
        if name == function and (suffix is None or file.endswith(suffix) or (suffix in ("os", "posixpath") and suffix in file)):
            found = (found or 0) + (tt if own else ct)
    return found


def cprofile(venv: Path, workspace: Path, env: dict[str, str], report: Path) -> None:
    with tempfile.NamedTemporaryFile(suffix=".prof", delete=False) as handle:
        out = handle.name
    start = time.perf_counter()
    subprocess.run([str(venv / "bin" / "python"), "-m", "cProfile", "-o", out, "-m", "roc", "work", "list", "-t"],
                   cwd=workspace, env=env, stdout=subprocess.DEVNULL, check=True)
    wall = time.perf_counter() - start
    stats = pstats.Stats(out)
    total = stats.total_tt
    print(f"\n3. cProfile of roc work list -t in {workspace.name} (process wall {wall * 1000:.0f} ms, "
          f"profiled {total * 1000:.0f} ms)")
    for label, suffix, function in PHASES:
        value = _phase_time(stats.stats, suffix, function)  # type: ignore[attr-defined]
        shown = f"{value * 1000:7.1f} ms {value / total * 100:5.1f} %" if value is not None else "   not called    "
        print(f"  {shown}  {label}")
    text = io.StringIO()
    pstats.Stats(out, stream=text).sort_stats("cumulative").print_stats(60)
    pstats.Stats(out, stream=text).sort_stats("tottime").print_stats(40)
    report.write_text(text.getvalue())
    print("  top functions by own time:")
    own = sorted(stats.stats.items(), key=lambda kv: -kv[1][2])[:12]  # type: ignore[attr-defined]
    for (file, line, name), (_, calls, tt, _, _) in own:
        where = f"{Path(file).name}:{line}" if line else file
        print(f"    {tt * 1000:6.1f} ms {calls:7d} calls  {name}  ({where})")
    print(f"  full listing: {report}")
    os.unlink(out)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--packages", type=int, default=1000, help="workspace size (1000)")
    parser.add_argument("--runs", type=int, default=10, help="runs per timing (10)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--venv", type=Path, default=HERE.parent / ".venv")
    parser.add_argument("--work", type=Path, default=HERE / ".work")
    args = parser.parse_args(argv)
    venv = args.venv.resolve()
    workspace = args.work / f"ws{args.packages}"
    ensure(workspace, args.packages, args.seed)
    envs = environments(venv)
    print(f"load average (1 min) at start: {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")
    process_times(venv, workspace, envs, args.runs)
    import_times(venv, workspace, envs["boot"], args.runs)
    cprofile(venv, workspace, envs["boot"], args.work / "list_profile.txt")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
