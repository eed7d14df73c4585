#!/usr/bin/env python3
"""Time ``roc work list -t`` against ``colcon list -t`` on generated workspaces.

    python bench/list_bench.py [--sizes 100 1000] [--roc-runs 10] [--colcon-runs 5] [--warmup 2]

For every workspace size (generated into ``bench/.work/wsN`` by gen_workspace.py, reused when present)
and for two environments, both tools run from the workspace root as separate processes, timed with
``time.perf_counter`` around ``subprocess.run``:

* ``plain``: neither ``_ROS_WHEELS_BOOTSTRAP_COMPLETE`` nor the wheels' ``LD_LIBRARY_PATH`` is set, so
  colcon's Python re-executes itself once through the ros-wheels-bootstrapper ``.pth`` (roc's command,
  bin/roc, sets what the bootstrapper would and starts Python once);
* ``boot``: both are set, as in an activated ROS environment, so no process re-executes.

Runs of the two tools are interleaved (after the warm-up runs) so that drift of the machine hits both
alike. The table shows median and minimum wall times, the ratio of the wall medians colcon/roc, and
the median CPU times (user + sys of each process and its children, from ``getrusage``), which
suffer less than wall times when other work runs on the machine. colcon writes a
``log/list_<time>`` directory per run (as it does for users); the workspace's ``log`` directory is
removed before each measurement so that every measurement starts alike.

Both tools must print the same lines; a mismatch (or a failing command) is reported with a diff and
the script exits 1. Missing the speed target (roc >= 10x faster at every size) is only reported.
"""

from __future__ import annotations

import argparse
import difflib
import os
import resource
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from gen_workspace import ensure  # noqa: E402

# roc's speed over colcon's at TARGET_SIZE packages or more: 60x from the discovery cache (issue 51), 10x
# without it (smaller workspaces are shown, not judged: colcon's own start-up dominates there)
TARGETS = {"plain": 60.0, "boot": 60.0, "cold": 10.0}
TARGET_SIZE = 1000
BOOT_FLAG = "_ROS_WHEELS_BOOTSTRAP_COMPLETE"


def wheel_library_path(venv: Path) -> str:
    """The LD_LIBRARY_PATH the bootstrapper sets: <venv>/lib and the wheels' ros_*.libs directories."""
    site = venv / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / "site-packages"
    parts = [str(venv / "lib")] + sorted(str(p.resolve()) for p in site.glob("ros_*.libs") if p.is_dir())
    return os.pathsep.join(parts)


def environments(venv: Path) -> dict[str, dict[str, str]]:
    """The ``plain`` and ``boot`` environments: this one, less or plus what the bootstrapper sets."""
    ours = set(wheel_library_path(venv).split(os.pathsep))
    base = {k: v for k, v in os.environ.items() if k != BOOT_FLAG}
    kept = [p for p in base.pop("LD_LIBRARY_PATH", "").split(os.pathsep) if p and p not in ours]
    if kept:
        base["LD_LIBRARY_PATH"] = os.pathsep.join(kept)
    boot = dict(base)
    boot[BOOT_FLAG] = "1"
    boot["LD_LIBRARY_PATH"] = os.pathsep.join([wheel_library_path(venv)] + kept)
    # "cold": as "boot", but roc's discovery cache can never be used (every run parses every manifest).
    cold = dict(boot, ROC_CACHE_DIR="/proc/roc-discovery-cache-disabled")
    return {"plain": base, "boot": boot, "cold": cold}


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_once(command: list[str], cwd: Path, env: dict[str, str]) -> tuple[float, float, subprocess.CompletedProcess]:
    """Wall time, CPU time (user + sys of the process and its children) and the result of one run."""
    cpu = _children_cpu()
    start = time.perf_counter()
    result = subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True)
    elapsed = time.perf_counter() - start
    cpu = _children_cpu() - cpu
    if result.returncode != 0:
        raise SystemExit(f"FAIL: {' '.join(command)} in {cwd} exited {result.returncode}:\n{result.stderr}")
    return elapsed, cpu, result


def check_same(size: int, variant: str, roc_out: str, colcon_out: str) -> None:
    if roc_out == colcon_out:
        return
    diff = difflib.unified_diff(colcon_out.splitlines(), roc_out.splitlines(), "colcon list -t",
                                "roc work list -t", lineterm="", n=1)
    shown = list(diff)[:40]
    print(f"\nFAIL: {size} packages ({variant}): roc and colcon print different lines:", file=sys.stderr)
    print("\n".join(shown), file=sys.stderr)
    raise SystemExit(1)


def measure(commands: dict[str, list[str]], runs: dict[str, int], warmup: int, cwd: Path,
            env: dict[str, str]) -> tuple[dict[str, list[float]], dict[str, list[float]], dict[str, str]]:
    """Wall and CPU times of the timed runs of each tool, and each tool's output."""
    outputs: dict[str, str] = {}
    for tool, command in commands.items():
        for _ in range(warmup):
            _, _, result = run_once(command, cwd, env)
            if tool in outputs and outputs[tool] != result.stdout:
                raise SystemExit(f"FAIL: {tool} printed different output from one run to the next")
            outputs[tool] = result.stdout
    times: dict[str, list[float]] = {tool: [] for tool in commands}
    cpus: dict[str, list[float]] = {tool: [] for tool in commands}
    for i in range(max(runs.values())):
        for tool, command in commands.items():
            if i < runs[tool]:
                elapsed, cpu, result = run_once(command, cwd, env)
                if result.stdout != outputs[tool]:
                    raise SystemExit(f"FAIL: {tool} printed different output from one run to the next")
                times[tool].append(elapsed)
                cpus[tool].append(cpu)
    return times, cpus, outputs


def remove_colcon_logs(workspace: Path) -> None:
    """colcon list writes a log/list_<time> directory per run; start every measurement without them."""
    log = workspace / "log"
    if (log / "COLCON_IGNORE").is_file():
        shutil.rmtree(log)


def ms(seconds: float) -> str:
    return f"{seconds * 1000:8.1f}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100, 1000], help="workspace sizes (packages)")
    parser.add_argument("--roc-runs", type=int, default=10, help="timed runs of roc per measurement (10)")
    parser.add_argument("--colcon-runs", type=int, default=5, help="timed runs of colcon per measurement (5)")
    parser.add_argument("--warmup", type=int, default=2, help="untimed runs of each tool first (2)")
    parser.add_argument("--variants", nargs="+", choices=["plain", "boot", "cold"], default=["plain", "boot", "cold"],
                        help="plain: every start pays the wheels' bootstrap re-exec; boot: it is done already "
                             "(a sourced environment); cold: boot without roc's discovery cache")
    parser.add_argument("--seed", type=int, default=0, help="generator seed (0)")
    parser.add_argument("--venv", type=Path, default=HERE.parent / ".venv", help="venv with roc and colcon")
    parser.add_argument("--work", type=Path, default=HERE / ".work", help="where workspaces are generated")
    args = parser.parse_args(argv)

    venv = args.venv.resolve()
    commands = {
        "roc": [str(venv / "bin" / "roc"), "work", "list", "-t"],
        "colcon": [str(venv / "bin" / "colcon"), "list", "-t"],
    }
    for command in commands.values():
        if not Path(command[0]).is_file():
            raise SystemExit(f"FAIL: {command[0]} not found (--venv)")
    runs = {"roc": args.roc_runs, "colcon": args.colcon_runs}
    envs = environments(venv)

    rows = []
    load_before = os.getloadavg()[0]
    for size in args.sizes:
        workspace = args.work / f"ws{size}"
        t0 = time.perf_counter()
        if ensure(workspace, size, args.seed):
            print(f"generated {workspace} ({time.perf_counter() - t0:.1f} s)", file=sys.stderr)
        for variant in args.variants:
            print(f"measuring {size} packages, {variant} ...", file=sys.stderr, flush=True)
            remove_colcon_logs(workspace)
            times, cpus, outputs = measure(commands, runs, args.warmup, workspace, envs[variant])
            check_same(size, variant, outputs["roc"], outputs["colcon"])
            lines = len(outputs["roc"].splitlines())
            if lines != size:
                raise SystemExit(f"FAIL: {size} packages generated but {lines} listed")
            roc_med, col_med = statistics.median(times["roc"]), statistics.median(times["colcon"])
            roc_cpu, col_cpu = statistics.median(cpus["roc"]), statistics.median(cpus["colcon"])
            rows.append((size, variant, roc_med, min(times["roc"]), col_med, min(times["colcon"]), col_med / roc_med,
                         roc_cpu, col_cpu, col_cpu / roc_cpu))

    print(f"\nroc work list -t vs colcon list -t  (roc: {args.roc_runs} runs, colcon: {args.colcon_runs} runs, "
          f"{args.warmup} warm-up each; times in ms; outputs identical)")
    print(f"{'':16}|{'wall time':^55}|{'CPU time (user+sys)':^33}")
    print(f"{'packages':>8}  {'env':<5} | {'roc med':>8}  {'roc min':>8}  {'colcon med':>10}  {'colcon min':>10}"
          f"  {'colcon/roc':>10} | {'roc med':>8}  {'colcon med':>10}  {'ratio':>7}")
    for size, variant, roc_med, roc_min, col_med, col_min, ratio, roc_cpu, col_cpu, cpu_ratio in rows:
        print(f"{size:>8}  {variant:<5} | {ms(roc_med)}  {ms(roc_min)}  {ms(col_med):>10}  {ms(col_min):>10}"
              f"  {ratio:>9.1f}x | {ms(roc_cpu)}  {ms(col_cpu):>10}  {cpu_ratio:>6.1f}x")
    load_after = os.getloadavg()[0]
    note = "  (busy machine: timings are noisy)" if max(load_before, load_after) > 1.0 else ""
    print(f"load average (1 min): {load_before:.2f} before, {load_after:.2f} after, "
          f"{os.cpu_count()} CPUs{note}")
    for variant in args.variants:
        mine = [row for row in rows if row[1] == variant and row[0] >= TARGET_SIZE]
        target = TARGETS[variant]
        if not mine:
            print(f"verdict ({variant}): not judged (the target is for {TARGET_SIZE} packages or more)")
            continue
        met = all(row[6] >= target for row in mine)
        detail = ", ".join(f"{row[6]:.1f}x at {row[0]} (CPU {row[9]:.1f}x)" for row in mine)
        print(f"verdict ({variant}): target roc >= {target:.0f}x faster from {TARGET_SIZE} packages: "
              f"{'MET' if met else 'MISSED'} ({detail})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
