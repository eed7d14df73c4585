#!/usr/bin/env python3
"""``roc tui`` in a real terminal on a graph of 200 topics (one rclpy process publishing each at 2 Hz;
tests/nodes/graph_node.py), roc's daemon warm, each measure beside its control in the same round:

1. the first painted screen: from starting ``roc tui`` in a pseudo-terminal of 80x24 to its first
   frame and to its first frame that shows the graph (the header's counts and the topics), and the
   CPU it used by then, median of ``--runs``; beside it the first frame of a minimal Textual app (one
   line of text: what Python and Textual alone take), ``roc topic list`` (the warm CLI answer) and,
   when the test oracle is installed, ``ros2 topic list`` with its daemon warm;
2. the CPU of ``roc tui`` (tmux, 80x24) while it refreshes the graph once a second (its rates stream
   measures all 200 topics), over ``--seconds``, as a share of one core; beside it ``roc topic hz`` on
   the same 200 topics (the same measurement printed as text), and the daemon's CPU during each;
3. a plot of a 1 kHz topic (std_msgs/Float64, a sine; bench/paced_publisher.py) in ``roc tui`` (tmux,
   100x30, opened from the palette: ``:plot /bench/fast data``): its CPU while it plots, and the
   samples it shows against those published; beside it a minimal rclpy subscriber counting the same
   messages (bench/counting_subscriber.py) and its CPU;
4. the rates on the screen against ``roc topic hz --format json`` run at the same time on the topics
   shown: the largest relative difference.

Each round prints the load average before and after it (the machine may be shared).

    python bench/tui_bench.py [--rounds 3] [--runs 5] [--seconds 20] [--topics 200]

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
import signal
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
BENCH = REPO / "bench"
BIN = Path(sys.executable).parent
ROC = str(BIN / "roc")
ORACLE = Path(os.environ.get("ROC_TEST_CACHE", Path.home() / ".cache" / "roc-tests")) / "ros2cli-venv" / "bin" / "ros2"
RATE_HZ = 2.0
PLOT_HZ = 1000.0
CONTROL_APP = """
from textual.app import App
from textual.widgets import Static


class Control(App):
    def compose(self):
        yield Static("textual control")


Control().run()
"""


class Terminal:
    """tmux on a private socket, no status line."""

    def __init__(self, directory: Path) -> None:
        self.socket = directory / "tmux.sock"
        self.config = directory / "tmux.conf"
        self.config.write_text("set -g status off\n")

    def tmux(self, *args: str) -> str:
        return subprocess.run(["tmux", "-S", str(self.socket), *args], capture_output=True, text=True).stdout

    def start(self, command: str, env: dict[str, str], size: tuple[int, int] = (80, 24)) -> psutil.Process:
        exports = " ".join(f"{k}={shlex.quote(v)}" for k, v in env.items() if k.startswith(("ROS_", "XDG_", "TERM")))
        self.tmux("-f", str(self.config), "new-session", "-d", "-x", str(size[0]), "-y", str(size[1]), "-s", "b",
                  f"env {exports} {command}; sleep 60")
        shell = psutil.Process(int(self.tmux("list-panes", "-t", "b", "-F", "#{pane_pid}").split()[0]))
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            for child in shell.children(recursive=True):
                if "tui" in child.cmdline():
                    return child
            time.sleep(0.01)
        raise RuntimeError("roc tui did not start")

    def screen(self) -> str:
        return self.tmux("capture-pane", "-p", "-t", "b")

    def keys(self, *keys: str, literal: bool = False) -> None:
        self.tmux("send-keys", "-t", "b", *(["-l"] if literal else []), *keys)

    def wait(self, condition, what: str, timeout: float = 60.0) -> str:
        deadline = time.monotonic() + timeout
        while True:
            screen = self.screen()
            if condition(screen):
                return screen
            if time.monotonic() > deadline:
                raise RuntimeError(f"timed out waiting for {what}; the screen:\n{screen}")
            time.sleep(0.2)

    def stop(self) -> None:
        self.tmux("kill-server")


def first_paint(command: list[str], env: dict[str, str], first: bytes, graph: bytes) -> tuple[float, float, float]:
    """Seconds from the start of ``command`` to the first frame holding ``first`` and to the first frame
    holding ``graph``, read from the pseudo-terminal of 80x24 it draws on; and the CPU time it had used
    by then (which a busy machine does not inflate as it does wall time)."""
    controller, terminal = pty.openpty()
    fcntl.ioctl(terminal, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 80, 0, 0))
    started = time.perf_counter()
    process = subprocess.Popen(command, env=env, stdin=terminal, stdout=terminal, stderr=terminal, close_fds=True,
                               start_new_session=True)
    os.close(terminal)
    output, painted = b"", None
    try:
        while True:
            ready, _, _ = select.select([controller], [], [], 30)
            if not ready:
                raise RuntimeError(f"{command[-2:]} showed nothing within 30 s: {output[-2000:]!r}")
            output += os.read(controller, 1 << 16)
            now = time.perf_counter() - started
            if painted is None and first in output:
                painted = now
            if graph in output:
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


def cpu_time(process: psutil.Process) -> float:
    times = process.cpu_times()
    return times.user + times.system


def cpu_share(process: psutil.Process, seconds: float) -> float:
    before = cpu_time(process)
    time.sleep(seconds)
    return (cpu_time(process) - before) / seconds


def daemon(env: dict[str, str]) -> psutil.Process:
    status = json.loads(subprocess.run([ROC, "daemon", "status", "--format", "json"], env=env, capture_output=True,
                                       text=True).stdout)
    return psutil.Process(status["pid"])


def shown_rates(screen: str) -> dict[str, float]:
    """topic -> rate (Hz) of the topics rows on the screen."""
    return {m.group(1): float(m.group(2)) for m in re.finditer(r"(/bench/t\d+)\s+\d+\s+\d+\s+([0-9.]+) Hz", screen)}


def ms(values: list[float]) -> str:
    return f"{statistics.median(values) * 1000:7.0f} ms"


def paint_round(env: dict[str, str], options, oracle: bool) -> dict[str, list[float]]:
    found: dict[str, list[float]] = {name: [] for name in ("first", "graph", "cpu", "control", "control_cpu", "list",
                                                           "ros2_list")}
    graph = f"{options.topics + 2} topics".encode()
    for _ in range(options.runs):  # interleaved, so that a change of load hits them alike
        first, shown, cpu = first_paint([ROC, "tui", "--no-workspace"], env, b"roc tui", graph)
        found["first"].append(first)
        found["graph"].append(shown)
        found["cpu"].append(cpu)
        control, _, control_cpu = first_paint([sys.executable, "-c", CONTROL_APP], env, b"textual control",
                                              b"textual control")
        found["control"].append(control)
        found["control_cpu"].append(control_cpu)
        found["list"].append(wall([ROC, "topic", "list"], env))
        if oracle:
            found["ros2_list"].append(wall([str(ORACLE), "topic", "list"], env))
    return found


def refresh_round(env: dict[str, str], terminal: Terminal, options) -> dict[str, float]:
    tui = terminal.start(f"{ROC} tui --no-workspace", env)
    terminal.wait(lambda s: len(shown_rates(s)) >= 5, "the rates on the screen")
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
    served.cpu_percent()
    hz_cpu = cpu_share(psutil.Process(hz_all.pid), options.seconds)
    daemon_with_hz = served.cpu_percent() / 100
    hz_all.terminate()
    hz_all.wait()
    return {"tui": tui_cpu, "daemon_tui": daemon_with_tui, "hz": hz_cpu, "daemon_hz": daemon_with_hz,
            "difference": max(differences) if differences else float("nan"), "compared": len(differences)}


PLOT_TITLE = re.compile(r"(\d+) samples, (\d+) lost")


def plot_round(env: dict[str, str], terminal: Terminal, options) -> dict[str, float]:
    """roc tui plotting a 1 kHz topic beside a minimal rclpy subscriber of it, both subscribed before
    the publisher starts; CPU over the middle of the publication, counts at its end."""
    tui = terminal.start(f"{ROC} tui --no-workspace", env, size=(100, 30))
    terminal.wait(lambda s: f"{options.topics + 2} topics" in s, "the graph")
    terminal.keys(":")
    terminal.wait(lambda s: "plot TOPIC FIELD" in s, "the palette")
    terminal.keys("plot /bench/fast data", literal=True)
    terminal.wait(lambda s: "plot /bench/fast data" in s, "the command typed")
    time.sleep(0.3)  # the palette's search settles on the typed view first
    terminal.keys("Enter")
    terminal.wait(lambda s: "plot, last 10 s" in s, "the plot")
    counter = subprocess.Popen([sys.executable, str(BENCH / "counting_subscriber.py"), "/bench/fast",
                                "type=std_msgs/msg/Float64"], env=env, stdout=subprocess.PIPE, text=True)
    assert counter.stdout is not None and counter.stdout.readline().strip() == "ready"
    seconds = options.seconds + 6
    publisher = subprocess.Popen([sys.executable, str(BENCH / "paced_publisher.py"), "/bench/fast", str(PLOT_HZ),
                                  str(seconds), "3", "sine", "steady"], env=env, stdout=subprocess.PIPE,
                                 stderr=subprocess.DEVNULL, text=True)
    time.sleep(3 + 3)  # matched, publishing, the plot drawing
    counted = psutil.Process(counter.pid)
    tui_before, counter_before, started = cpu_time(tui), cpu_time(counted), time.monotonic()
    time.sleep(options.seconds)
    elapsed = time.monotonic() - started
    tui_cpu, counter_cpu = (cpu_time(tui) - tui_before) / elapsed, (cpu_time(counted) - counter_before) / elapsed
    published = json.loads(publisher.communicate()[0])
    time.sleep(1.5)  # the last batches on their way
    counter.send_signal(signal.SIGINT)
    subscriber = json.loads(counter.communicate()[0].splitlines()[-1])
    try:
        shown = terminal.wait(lambda s: bool((found := PLOT_TITLE.search(s)) and int(found.group(1)) >= published["count"]),
                              "every sample on the plot", timeout=10)
    except RuntimeError:
        shown = terminal.screen()  # fewer: what it shows is the result
    match = PLOT_TITLE.search(shown)
    assert match is not None, shown
    terminal.stop()
    return {"tui": tui_cpu, "counter": counter_cpu, "published": published["count"], "rate": published["rate"],
            "shown": int(match.group(1)), "lost": int(match.group(2)), "subscriber": subscriber["count"]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
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
    publisher = subprocess.Popen([sys.executable, str(REPO / "tests" / "nodes" / "graph_node.py"), json.dumps(spec)],
                                 env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    terminal = Terminal(work)
    oracle = ORACLE.exists()
    try:
        assert publisher.stdout is not None and publisher.stdout.readline().strip() == "ready"
        subprocess.run([ROC, "daemon", "start"], env=env, capture_output=True, check=True)
        while options.topics + 2 > len(json.loads(subprocess.run(
                [ROC, "topic", "list", "--format", "json"], env=env, capture_output=True, text=True).stdout)):
            time.sleep(0.2)
        if oracle:
            subprocess.run([str(ORACLE), "daemon", "start"], env=env, capture_output=True)
            wall([str(ORACLE), "topic", "list"], env)
        print(f"{os.cpu_count()} cores; {options.topics} topics at {RATE_HZ:g} Hz; the daemon warm")
        for number in range(1, options.rounds + 1):
            before = os.getloadavg()[0]
            paint = paint_round(env, options, oracle)
            refresh = refresh_round(env, terminal, options)
            plot = plot_round(env, terminal, options)
            print(f"round {number}: load average {before:.1f} before, {os.getloadavg()[0]:.1f} after")
            print(f"  1. first painted screen (median of {options.runs}):")
            print(f"     roc tui, first frame               {ms(paint['first'])} (goal < 300 ms)")
            print(f"     roc tui, first frame with the graph {ms(paint['graph'])}, CPU by then {ms(paint['cpu'])}")
            print(f"     minimal Textual app, first frame   {ms(paint['control'])}, CPU by then "
                  f"{ms(paint['control_cpu'])}  (roc tui / it: first frame "
                  f"{statistics.median(paint['first']) / statistics.median(paint['control']):.2f}, graph "
                  f"{statistics.median(paint['graph']) / statistics.median(paint['control']):.2f})")
            print(f"     roc topic list                     {ms(paint['list'])}")
            if paint["ros2_list"]:
                print(f"     ros2 topic list                    {ms(paint['ros2_list'])}  (roc tui's graph / it: "
                      f"{statistics.median(paint['graph']) / statistics.median(paint['ros2_list']):.2f})")
            print(f"  2. refreshing every second, CPU over {options.seconds:g} s: roc tui {refresh['tui'] * 100:.1f} % "
                  f"of a core (goal <= 3 %), daemon {refresh['daemon_tui'] * 100:.1f} %; roc topic hz on the "
                  f"{options.topics} topics {refresh['hz'] * 100:.1f} % (ratio "
                  f"{refresh['tui'] / refresh['hz'] if refresh['hz'] else float('inf'):.2f}), daemon "
                  f"{refresh['daemon_hz'] * 100:.1f} %")
            print(f"  3. a plot of {plot['rate']:.0f} Hz, CPU over {options.seconds:g} s: roc tui {plot['tui'] * 100:.1f} % "
                  f"of a core (goal <= 10 %); a minimal rclpy subscriber {plot['counter'] * 100:.1f} % (ratio "
                  f"{plot['tui'] / plot['counter'] if plot['counter'] else float('inf'):.2f}); samples shown "
                  f"{plot['shown']} of {plot['published']} published ({plot['lost']} lost), the subscriber "
                  f"{plot['subscriber']}")
            print(f"  4. rates shown against roc topic hz on the {refresh['compared']} topics on screen: largest "
                  f"difference {refresh['difference'] * 100:.2f} % (goal < 1 %)")
    finally:
        terminal.stop()
        subprocess.run([ROC, "daemon", "stop"], env=env, capture_output=True)
        if oracle:
            subprocess.run([str(ORACLE), "daemon", "stop"], env=env, capture_output=True)
        publisher.terminate()
        publisher.wait()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
