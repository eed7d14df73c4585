#!/usr/bin/env python3
"""``roc tui`` in a real terminal (tmux, 80x24) on a graph of 200 topics (one rclpy process publishing
each at 2 Hz; tests/nodes/graph_node.py), roc's daemon warm:

1. time to the first painted screen: from starting ``roc tui`` (in a pseudo-terminal of 80x24) to
   its first frame, and to the first frame that shows the graph (the header's counts and the topics), median of
   ``--runs``; beside it, in the same runs, ``roc topic list`` (the warm CLI answer, the control) and,
   when the test oracle is installed, ``ros2 topic list`` with its daemon warm;
2. CPU of the ``roc tui`` process while it refreshes the graph once a second (its rates stream
   measures all 200 topics), over ``--seconds``, as a share of one core; beside it the CPU of
   ``roc topic hz`` on the same 200 topics (the control: the same measurement, printed as text), and the
   daemon's CPU during each;
3. the rates it shows against ``roc topic hz --format json`` run at the same time on the topics on
   the screen: the largest relative difference (goal: below 1 %).

    python bench/tui_bench.py [--runs 5] [--seconds 20] [--topics 200]

ROS domain 93, localhost discovery, roc's daemon in a private runtime directory.
"""

from __future__ import annotations

import argparse
import fcntl
import json
import os
import pty
import re
import select
import shlex
import shutil
import statistics
import struct
import subprocess
import sys
import tempfile
import termios
import time
from pathlib import Path

import psutil

REPO = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
ROC = str(BIN / "roc")
ORACLE = Path(os.environ.get("ROC_TEST_CACHE", Path.home() / ".cache" / "roc-tests")) / "ros2cli-venv" / "bin" / "ros2"
RATE_HZ = 2.0


class Terminal:
    """tmux on a private socket, 80x24, no status line."""

    def __init__(self, directory: Path) -> None:
        self.socket = directory / "tmux.sock"
        self.config = directory / "tmux.conf"
        self.config.write_text("set -g status off\n")

    def tmux(self, *args: str) -> str:
        return subprocess.run(["tmux", "-S", str(self.socket), *args], capture_output=True, text=True).stdout

    def start(self, command: str, env: dict[str, str]) -> None:
        exports = " ".join(f"{k}={shlex.quote(v)}" for k, v in env.items() if k.startswith(("ROS_", "XDG_", "TERM")))
        self.tmux("-f", str(self.config), "new-session", "-d", "-x", "80", "-y", "24", "-s", "b",
                  f"env {exports} {command}; sleep 60")

    def screen(self) -> str:
        return self.tmux("capture-pane", "-p", "-t", "b")

    def roc_process(self) -> psutil.Process:
        shell = psutil.Process(int(self.tmux("list-panes", "-t", "b", "-F", "#{pane_pid}").split()[0]))
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            for child in shell.children(recursive=True):
                if "roc" in " ".join(child.cmdline()) and "tui" in child.cmdline():
                    return child
            time.sleep(0.01)
        raise RuntimeError("roc tui did not start")

    def stop(self) -> None:
        self.tmux("kill-server")


def first_paint(env: dict[str, str], topics: int) -> tuple[float, float, float]:
    """Seconds from the start of roc tui to its first frame, and to the first frame with the graph,
    read from the pseudo-terminal it draws on (80x24); and the CPU time roc tui had used by then
    (which a busy machine does not inflate as it does wall time)."""
    controller, terminal = pty.openpty()
    fcntl.ioctl(terminal, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 80, 0, 0))
    started = time.perf_counter()
    process = subprocess.Popen([ROC, "tui", "--no-workspace"], env=env, stdin=terminal, stdout=terminal,
                               stderr=terminal, close_fds=True, start_new_session=True)
    os.close(terminal)
    output, painted = b"", None
    try:
        while True:
            ready, _, _ = select.select([controller], [], [], 30)
            if not ready:
                raise RuntimeError(f"roc tui showed no graph within 30 s: {output[-2000:]!r}")
            output += os.read(controller, 1 << 16)
            now = time.perf_counter() - started
            if painted is None and b"roc tui" in output:
                painted = now
            if f"{topics + 2} topics".encode() in output and b"/bench/t000" in output:
                cpu = psutil.Process(process.pid).cpu_times()
                return painted or now, now, cpu.user + cpu.system
    finally:
        process.terminate()
        process.wait()
        os.close(controller)


def wall(command: list[str], env: dict[str, str]) -> float:
    started = time.perf_counter()
    subprocess.run(command, env=env, capture_output=True, check=True)
    return time.perf_counter() - started


def cpu_share(process: psutil.Process, seconds: float) -> float:
    before = process.cpu_times()
    time.sleep(seconds)
    after = process.cpu_times()
    return (after.user + after.system - before.user - before.system) / seconds


def daemon(env: dict[str, str]) -> psutil.Process:
    status = json.loads(subprocess.run([ROC, "daemon", "status", "--format", "json"], env=env, capture_output=True,
                                       text=True).stdout)
    return psutil.Process(status["pid"])


def shown_rates(screen: str) -> dict[str, float]:
    """topic -> rate (Hz) of the topics rows on the screen."""
    return {m.group(1): float(m.group(2)) for m in re.finditer(r"(/bench/t\d+)\s+\d+\s+\d+\s+([0-9.]+) Hz", screen)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--topics", type=int, default=200)
    options = parser.parse_args()
    if shutil.which("tmux") is None:
        sys.exit("tui_bench: tmux is needed (apt-get install tmux)")
    work = Path(tempfile.mkdtemp(prefix="roc-tui-bench-"))
    (work / "runtime").mkdir()
    env = {**os.environ, "ROS_DOMAIN_ID": "93", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
           "XDG_RUNTIME_DIR": str(work / "runtime"), "TERM": "xterm-256color"}
    env.pop("ROS_LOCALHOST_ONLY", None)
    spec = {"name": "many", "publishers": [{"topic": f"bench/t{i:03d}", "type": "std_msgs/msg/String",
                                            "values": {"data": "x" * 64}, "rate_hz": RATE_HZ}
                                           for i in range(options.topics)]}
    publisher = subprocess.Popen([sys.executable, str(REPO / "tests" / "nodes" / "graph_node.py"), json.dumps(spec)], env=env,
                                 stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    terminal = Terminal(work)
    try:
        assert publisher.stdout.readline().strip() == "ready"
        subprocess.run([ROC, "daemon", "start"], env=env, capture_output=True, check=True)
        while options.topics + 2 > len(json.loads(subprocess.run(
                [ROC, "topic", "list", "--format", "json"], env=env, capture_output=True, text=True).stdout)):
            time.sleep(0.2)
        oracle = ORACLE.exists()
        if oracle:
            subprocess.run([str(ORACLE), "daemon", "start"], env=env, capture_output=True)
            wall([str(ORACLE), "topic", "list"], env)
        paints, datas, cpus, lists, ros2_lists = [], [], [], [], []
        for _ in range(options.runs):
            paint, data, cpu = first_paint(env, options.topics)
            paints.append(paint)
            datas.append(data)
            cpus.append(cpu)
            lists.append(wall([ROC, "topic", "list"], env))
            if oracle:
                ros2_lists.append(wall([str(ORACLE), "topic", "list"], env))
        print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
        print(f"1. first painted screen (median of {options.runs}, daemon warm, {options.topics} topics):")
        print(f"   roc tui, first frame:          {statistics.median(paints) * 1000:7.0f} ms")
        print(f"   roc tui, first frame of graph: {statistics.median(datas) * 1000:7.0f} ms (goal < 500 ms)")
        print(f"   roc tui, CPU time by then:     {statistics.median(cpus) * 1000:7.0f} ms")
        print(f"   roc topic list (control):      {statistics.median(lists) * 1000:7.0f} ms "
              f"(ratio {statistics.median(datas) / statistics.median(lists):.1f})")
        if ros2_lists:
            print(f"   ros2 topic list (oracle):      {statistics.median(ros2_lists) * 1000:7.0f} ms "
                  f"(ratio {statistics.median(datas) / statistics.median(ros2_lists):.2f})")

        terminal.start(f"{ROC} tui --no-workspace", env)
        tui = terminal.roc_process()
        deadline = time.monotonic() + 60
        while len(shown_rates(terminal.screen())) < 10 and time.monotonic() < deadline:
            time.sleep(0.5)
        time.sleep(5)  # the rates stream of every topic running, the windows filling
        served = daemon(env)
        served.cpu_percent()
        hz = subprocess.Popen([ROC, "topic", "hz", "--format", "json", *shown_rates(terminal.screen())], env=env,
                              stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        tui_cpu = cpu_share(tui, options.seconds)
        screen = terminal.screen()
        hz.terminate()
        last: dict[str, float] = {}
        for line in hz.communicate()[0].splitlines():
            entry = json.loads(line)
            last[entry["topic"]] = entry["rate"]
        shown = shown_rates(screen)
        differences = [abs(shown[t] - last[t]) / last[t] for t in shown if t in last]
        terminal.stop()
        daemon_with_tui = served.cpu_percent() / 100
        everything = [f"/bench/t{i:03d}" for i in range(options.topics)]
        hz_all = subprocess.Popen([ROC, "topic", "hz", *everything], env=env, stdout=subprocess.DEVNULL,
                                  stderr=subprocess.DEVNULL)
        time.sleep(5)
        hz_process = psutil.Process(hz_all.pid)
        served.cpu_percent()
        hz_cpu = cpu_share(hz_process, options.seconds)
        daemon_with_hz = served.cpu_percent() / 100
        hz_all.terminate()
        hz_all.wait()
        print(f"2. CPU over {options.seconds:g} s, {options.topics} topics at {RATE_HZ:g} Hz, refreshed every second:")
        print(f"   roc tui:                        {tui_cpu * 100:5.1f} % of a core (goal < 10 %); daemon "
              f"{daemon_with_tui * 100:.1f} %")
        print(f"   roc topic hz, all topics:       {hz_cpu * 100:5.1f} % of a core (control; ratio "
              f"{tui_cpu / hz_cpu if hz_cpu else float('inf'):.2f}); daemon {daemon_with_hz * 100:.1f} %")
        print(f"3. rates shown against roc topic hz on the {len(differences)} topics on screen: largest difference "
              f"{max(differences) * 100 if differences else float('nan'):.2f} % (goal < 1 %); shown "
              f"{sorted(set(shown.values()))}, hz {sorted({round(v, 3) for v in last.values()})}")
    finally:
        terminal.stop()
        subprocess.run([ROC, "daemon", "stop"], env=env, capture_output=True)
        if ORACLE.exists():
            subprocess.run([str(ORACLE), "daemon", "stop"], env=env, capture_output=True)
        publisher.terminate()
        publisher.wait()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
