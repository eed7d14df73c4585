#!/usr/bin/env python3
"""Start-up of a 10-node system, ``roc launch`` against ``ros2 launch``, side by side in one run: the time
from the command to "all ten nodes visible in the graph", and the CPU the launcher uses while it
supervises the running system.

    .venv/bin/python bench/launch_bench.py [--rounds 10] [--idle-seconds 10]

The system: ``ten.launch.py`` of the tests' package roc_launch_demo (workspaces/fixtures/launch: ten rclpy
talkers at 1 Hz in namespace /bench), built by roc into bench/.work/launch_ws. Variants, interleaved in
each round:

- ``ros2 launch roc_launch_demo ten.launch.py namespace:=NS`` (the oracle, from the tests' ros2cli venv);
- ``roc launch roc_launch_demo ten.launch.py namespace:=NS`` (the same file, the same launch library);
- ``roc launch NS``: the same ten processes declared in roc.toml (roc's own supervisor, no launch library);
- ``roc launch --no-warm-start roc_launch_demo ten.launch.py ...``: the file again, each node started by exec
  as ros2 launch starts it (what the warm start, docs/commands/launch.md, saves).

Each start uses a namespace of its own (a node that left uncleanly can stay in the observer's graph for a
while, which must not delay or fool the next round).

The observer is an rclpy node of this process, in ROS domain 97 with localhost discovery, created before
the rounds and using roc's Fast DDS participant profile (announcements every 0.5 s): with Fast DDS's 3 s a
node whose first announcements the observer missed is seen up to 3 s late, noise that would swamp the
launchers' difference (the launched processes keep Fast DDS's defaults). Each round starts once the
launcher of the round before has ended. Times: median, min and max over the rounds; the ratio is of medians.
A second table gives, for the same rounds, the time from the command to the tenth talker's process
started (from /proc: the launcher's own part, without the nodes' start-up and discovery, which vary
from start to start by more than the launchers differ).

Idle CPU: after the last round, each launcher (plain output, not a terminal) runs the system for a few
seconds, then the CPU time of the launcher's own processes (roc: roc, its guard, its fork server and, for a
launch file, the launch runner; ros2: the ros2 launch process) over ``--idle-seconds``, in percent of one
core. roc's live view is measured too, on a pseudo-terminal. Beside it, the memory of the ten talkers: the
sum of their PSS (each shared page counted once, split between its users), and of their RSS.
"""

from __future__ import annotations

import argparse
import os
import pty
import shutil
import signal
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))
from helpers.graph import ORACLE_VENV, install_oracle  # noqa: E402

WORK = REPO / "bench" / ".work" / "launch_ws"
DOMAIN = "97"

def nodes(namespace: str) -> set[str]:
    return {f"/{namespace}/talker_{i}" for i in range(10)}
ROC = str(Path(sys.executable).parent / "roc")
SITE = f"lib/python{sys.version_info.major}.{sys.version_info.minor}/site-packages"


def system(namespace: str) -> str:
    """The ten talkers as a roc.toml system named after their namespace."""
    return f"[launch.{namespace}]\n" + "".join(
        f'[[launch.{namespace}.process]]\npackage = "roc_launch_demo"\nexecutable = "talker"\nname = "talker_{i}"\n'
        f'namespace = "{namespace}"\nparameters = {{ rate = 1.0 }}\n' for i in range(10))


def build(namespaces: list[str]) -> Path:
    """roc_launch_demo built by roc (again when the fixture changed), and a roc.toml with one system per
    namespace; its install prefix."""
    fixture = REPO / "workspaces" / "fixtures" / "launch"
    stamp = WORK / ".fixture"
    state = "".join(f"{p}:{p.stat().st_mtime_ns}\n" for p in sorted(fixture.rglob("*")) if p.is_file())
    if not stamp.is_file() or stamp.read_text() != state:
        shutil.rmtree(WORK, ignore_errors=True)
        shutil.copytree(fixture, WORK)
        subprocess.run([ROC, "work", "build"], cwd=WORK, env={**os.environ, "AMENT_PREFIX_PATH": sys.prefix},
                       check=True, capture_output=True)
        stamp.write_text(state)
    (WORK / "roc.toml").write_text("".join(system(namespace) for namespace in namespaces))
    return WORK / "install" / "roc_launch_demo"


def environment(prefix: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("ROS_LOCALHOST_ONLY", "FASTRTPS_DEFAULT_PROFILES_FILE",
                                                            "FASTDDS_DEFAULT_PROFILES_FILE")}
    env.update(ROS_DOMAIN_ID=DOMAIN, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
               AMENT_PREFIX_PATH=os.pathsep.join([str(prefix), str(ORACLE_VENV), sys.prefix]),
               PYTHONPATH=os.pathsep.join(filter(None, [str(prefix / SITE), os.environ.get("PYTHONPATH")])))
    return env


# Each start of a variant puts its nodes in a namespace of their own (a node that left uncleanly may stay in
# the observer's graph for a while): the command for a namespace.
VARIANTS = {
    "ros2 launch (file)": lambda ns: [str(ORACLE_VENV / "bin" / "ros2"), "launch", "roc_launch_demo", "ten.launch.py",
                                      f"namespace:={ns}"],
    "roc launch (file)": lambda ns: [ROC, "launch", "--log-base", "/dev/null", "roc_launch_demo", "ten.launch.py",
                                     f"namespace:={ns}"],
    "roc launch (roc.toml)": lambda ns: [ROC, "launch", "--log-base", "/dev/null", ns],
    "roc launch (file, cold)": lambda ns: [ROC, "launch", "--log-base", "/dev/null", "--no-warm-start",
                                           "roc_launch_demo", "ten.launch.py", f"namespace:={ns}"],
}


class Observer:
    def __init__(self) -> None:
        os.environ.update(ROS_DOMAIN_ID=DOMAIN, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
                          FASTRTPS_DEFAULT_PROFILES_FILE=str(REPO / "roc" / "ros" / "fastdds_participant.xml"))
        import rclpy
        from rclpy.node import Node

        rclpy.init()
        self.rclpy = rclpy
        self.node = Node("launch_bench_observer")

    def seen(self) -> set[str]:
        self.rclpy.spin_once(self.node, timeout_sec=0.005)
        return {f"{namespace.rstrip('/')}/{name}" for name, namespace in self.node.get_node_names_and_namespaces()}

    def wait(self, done, timeout: float) -> bool:
        deadline = time.monotonic() + timeout
        while not done(self.seen()):
            if time.monotonic() > deadline:
                return False
        return True


def one_round(observer: Observer, name: str, namespace: str, env: dict[str, str]) -> tuple[float, float]:
    """Seconds from the command to all ten nodes visible, and to the tenth node's process started."""
    command, expected = VARIANTS[name](namespace), nodes(namespace)
    start = time.perf_counter()
    launcher = subprocess.Popen(command, cwd=WORK, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
    try:
        if not observer.wait(lambda seen: expected <= seen, 60):
            raise SystemExit(f"{command[:3]}: the ten nodes did not appear within 60 s")
        return time.perf_counter() - start, last_spawn(launcher.pid)
    finally:
        time.sleep(1)  # every node past its start-up (a node interrupted while it starts may exit uncleanly)
        launcher.send_signal(signal.SIGINT)
        launcher.wait(timeout=60)


def last_spawn(root: int) -> float:
    """Seconds from the launcher's start to the start of its last talker, both read from /proc (one clock,
    in steps of 10 ms): the part of the start-up the launcher controls, without the nodes' own start-up and
    discovery."""
    import psutil

    launcher = psutil.Process(root)
    return max(p.create_time() for p in talkers(launcher)) - launcher.create_time()


def talkers(launcher) -> list:
    return [p for p in launcher.children(recursive=True) if "talker" in " ".join(p.cmdline())]


def launcher_processes(root: int) -> list[int]:
    """The launcher's own processes: it, and its descendants that are not launched nodes."""
    import psutil

    parent = psutil.Process(root)
    found = [parent]
    for child in parent.children(recursive=True):
        command = " ".join(child.cmdline())
        if "roc.launch" in command or "guard.py" in command or "forkserver.py" in command:
            found.append(child)
    return [p.pid for p in found]


def idle_cpu(observer: Observer, name: str, namespace: str, env: dict[str, str], seconds: float,
             terminal: bool) -> tuple[float, float, float]:
    """Percent of one core used by the launcher's own processes while the system runs; the MiB of the ten
    talkers' PSS and RSS."""
    import psutil

    command, expected = VARIANTS[name](namespace), nodes(namespace)
    if terminal:
        pid, fd = pty.fork()
        if pid == 0:
            os.chdir(WORK)
            os.execve(command[0], command, {**env, "TERM": "xterm", "COLUMNS": "150", "LINES": "40"})
        drain = subprocess.Popen(["cat"], stdin=fd, stdout=subprocess.DEVNULL,  # keeps the terminal read
                                 stderr=subprocess.DEVNULL)
    else:
        launcher = subprocess.Popen(command, cwd=WORK, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                    stderr=subprocess.DEVNULL)
        pid = launcher.pid
    try:
        observer.wait(lambda seen: expected <= seen, 60)
        time.sleep(3)  # start-up is over
        processes = [psutil.Process(p) for p in launcher_processes(pid)]

        def cpu() -> float:
            return sum(sum(p.cpu_times()[:2]) for p in processes)

        before, started = cpu(), time.perf_counter()
        time.sleep(seconds)
        percent = 100 * (cpu() - before) / (time.perf_counter() - started)
        memory = [p.memory_full_info() for p in talkers(psutil.Process(pid))]
        return percent, sum(m.pss for m in memory) / 2**20, sum(m.rss for m in memory) / 2**20
    finally:
        os.kill(pid, signal.SIGINT)
        if terminal:
            os.waitpid(pid, 0)
            drain.wait(timeout=30)
            os.close(fd)
        else:
            launcher.wait(timeout=60)


def table(title: str, times: dict[str, list[float]]) -> None:
    oracle = statistics.median(times["ros2 launch (file)"])
    print(f"\n{title}")
    print(f"{'variant':<24}{'median':>9}{'min':>8}{'max':>8}{'vs ros2':>9}")
    for name, values in times.items():
        median = statistics.median(values)
        print(f"{name:<24}{median:>8.2f}s{min(values):>7.2f}s{max(values):>7.2f}s{median / oracle:>8.2f}x")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=10)
    parser.add_argument("--idle-seconds", type=float, default=10.0)
    args = parser.parse_args()
    reason = install_oracle(launch=True)
    if reason:
        raise SystemExit(f"ros2 launch is not available: {reason}")
    kinds = [f"v{index}_" for index in range(len(VARIANTS))]
    namespaces = [f"{kind}{n}" for n in range(args.rounds) for kind in kinds]
    namespaces += ["idle_ros2", "idle_file", "idle_toml", "idle_view", "idle_cold"]
    env = environment(build(namespaces))
    observer = Observer()
    observer.wait(lambda _seen: False, 2)  # the observer joins the domain
    times: dict[str, list[float]] = {name: [] for name in VARIANTS}
    spawns: dict[str, list[float]] = {name: [] for name in VARIANTS}
    for round_number in range(args.rounds):
        for name, kind in zip(VARIANTS, kinds):
            visible, spawned = one_round(observer, name, f"{kind}{round_number}", env)
            times[name].append(visible)
            spawns[name].append(spawned)
        print(f"round {round_number + 1}: " + ", ".join(f"{n} {t[-1]:.2f} s" for n, t in times.items()), flush=True)
    table(f"time from the command to all 10 nodes visible ({args.rounds} rounds, interleaved)", times)
    table("time from the command to the 10th node's process started (the launcher's own part)", spawns)
    print(f"\nlauncher CPU while supervising the running system ({args.idle_seconds:g} s, % of one core), "
          "and the ten talkers' memory")
    print(f"{'variant':<36}{'CPU':>8}{'PSS':>10}{'RSS':>10}")
    idle = [("ros2 launch (file)", "idle_ros2", False), ("roc launch (file)", "idle_file", False),
            ("roc launch (roc.toml)", "idle_toml", False), ("roc launch (file)", "idle_view", True),
            ("roc launch (file, cold)", "idle_cold", False)]
    for name, namespace, terminal in idle:
        percent, pss, rss = idle_cpu(observer, name, namespace, env, args.idle_seconds, terminal)
        print(f"{name + (', live view' if terminal else ''):<36}{percent:>6.2f} %{pss:>6.0f} MiB{rss:>6.0f} MiB",
              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
