#!/usr/bin/env python3
"""How long a process on another host outlives a failure of the launcher's side: ``roc launch`` (its guard
on the host, roc/launch/remote_guard.py) beside what people script by hand, ``ssh HOST CMD`` and
``ssh -t HOST CMD`` (a terminal, so sshd sends SIGHUP when the connection closes), side by side in one run.

    .venv/bin/python bench/launch_remote_bench.py [--rounds 5] [--patience 20]

The host: an sshd this script starts on 127.0.0.1 (tests/launch/ssh_server.py: a throwaway key, its own
configuration, reached through a relay that can cut the connection without closing it); the process:
``listener`` of the tests' package roc_launch_demo, built by roc into bench/.work/remote_ws and sourced on
the host by its install's setup.bash. The failures, each round:

- the SSH connection killed: the ssh client process (SIGKILL), and the sshd session process (SIGKILL);
- the network cut: the relay stops carrying anything, without closing either side;
- the launcher killed (SIGKILL): roc; for plain ssh, the shell that ran it (ssh itself lives on).

For roc, one ``roc launch`` of a system with a local talker and the remote listener (``respawn = true``,
tests/helpers/ssh.py) per round goes through the failures in that order (each respawn gives the next failure a fresh process).
Each time: the seconds from the failure until the remote process is gone (read in /proc every 10 ms), or
"still running" after ``--patience`` seconds (then the script stops it itself). Median, min and max over
the rounds.
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))
from helpers.launch import SITE, build_demo  # noqa: E402
from helpers.ssh import REMOTE, alive, ancestors, comm, ssh_server, sshd_session, write_pair  # noqa: E402

WORK = REPO / "bench" / ".work" / "remote_ws"
ROC = str(Path(sys.executable).parent / "roc")
DOMAIN = "96"
FAILURES = ("ssh client killed", "sshd session killed", "network cut", "launcher killed")


def stopped_after(pid: int, patience: float) -> float | None:
    """Seconds until ``pid`` has ended, None if it still runs after ``patience`` (then it is killed)."""
    started = time.monotonic()
    while time.monotonic() - started < patience:
        if not alive(pid):
            return time.monotonic() - started
        time.sleep(0.01)
    os.kill(pid, signal.SIGKILL)
    return None


def wait_for(condition, timeout: float, what: str):
    deadline = time.monotonic() + timeout
    while not (value := condition()):
        if time.monotonic() > deadline:
            raise SystemExit(f"timed out waiting for {what}")
        time.sleep(0.05)
    return value


def roc_round(env: dict[str, str], directory: Path, server, patience: float) -> dict[str, float | None]:
    log = directory / "roc.log"
    with open(log, "w") as output:
        roc = subprocess.Popen([ROC, "launch", "pair", "--log-base", os.devnull], cwd=directory, env=env,
                               stdin=subprocess.DEVNULL, stdout=output, stderr=subprocess.STDOUT)

    def ready(count: int) -> int:
        text = log.read_text(errors="replace")
        pids = re.findall(rf"\[INFO\] \[{REMOTE}\]: process started with pid \[(\d+)\]", text)
        return int(pids[-1]) if len(pids) == count and text.count("[local.far_listener]: ready") >= count else 0

    import psutil

    fail = {
        "ssh client killed": lambda _pid: os.kill(next(p.pid for p in psutil.Process(roc.pid).children()
                                                     if p.name() == "ssh"), signal.SIGKILL),
        "sshd session killed": lambda pid: os.kill(sshd_session(pid), signal.SIGKILL),
        "network cut": lambda _pid: server.relay.cut(),
        "launcher killed": lambda _pid: roc.kill(),
    }
    times = {}
    try:
        for count, failure in enumerate(FAILURES, 1):
            pid = wait_for(lambda n=count: ready(n), 90, f"start {count} of the remote process; roc's output:\n"
                           f"{log.read_text(errors='replace')}")
            fail[failure](pid)
            times[failure] = stopped_after(pid, patience)
    finally:
        roc.kill()
        roc.wait()
    return times


def ssh_round(env: dict[str, str], server, prefix: Path, terminal: bool, patience: float) -> dict[str, float | None]:
    """``ssh [-t] robot 'source setup.bash; exec listener'`` run by a shell, as a hand-written script does."""
    command = f"source {prefix.parent}/setup.bash && exec {prefix}/lib/roc_launch_demo/listener"
    ssh = f"ssh -F {server.config} {'-tt' if terminal else ''} robot {command!r}"
    times = {}
    for failure in FAILURES:
        shell = subprocess.Popen(["bash", "-c", f"{ssh}; true"], env=env, stdin=subprocess.PIPE if terminal else
                                 subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                 start_new_session=True)
        import psutil

        def listener() -> int:
            found = [p.pid for p in psutil.process_iter(["cmdline"])
                     if p.info["cmdline"] and p.info["cmdline"][-1].endswith("roc_launch_demo/listener")
                     and "sshd" in {comm(a) for a in ancestors(p.pid)}]
            return found[0] if len(found) == 1 else 0

        pid = wait_for(listener, 60, "the listener started by ssh")
        time.sleep(1.0)  # settled, as roc's round waits for the node's first line
        client = next(p.pid for p in psutil.Process(shell.pid).children() if p.name() == "ssh")
        if failure == "ssh client killed":
            os.kill(client, signal.SIGKILL)
        elif failure == "sshd session killed":
            os.kill(sshd_session(pid), signal.SIGKILL)
        elif failure == "network cut":
            server.relay.cut()
        else:
            os.kill(shell.pid, signal.SIGKILL)
        times[failure] = stopped_after(pid, patience)
        for process in (client, shell.pid):
            try:
                os.kill(process, signal.SIGKILL)
            except ProcessLookupError:
                pass
        shell.wait()
    return times


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--patience", type=float, default=20.0, help="seconds to wait for a process to stop")
    args = parser.parse_args()
    if not (WORK / "ws" / "install").is_dir():
        WORK.mkdir(parents=True, exist_ok=True)
        build_demo(WORK)
    prefix = WORK / "ws" / "install" / "roc_launch_demo"
    results: dict[str, dict[str, list[float | None]]] = {}
    with tempfile.TemporaryDirectory() as scratch, ssh_server(Path(scratch) / "ssh") as server:
        env = {**os.environ, **server.env(), "ROS_DOMAIN_ID": DOMAIN, "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
               "AMENT_PREFIX_PATH": os.pathsep.join([str(prefix), sys.prefix]),
               "PYTHONPATH": str(prefix / SITE)}
        write_pair(Path(scratch), prefix, respawn=True)
        for round_number in range(args.rounds):
            for name, measure in (("roc launch", lambda: roc_round(env, Path(scratch), server, args.patience)),
                                  ("ssh HOST CMD", lambda: ssh_round(env, server, prefix, False, args.patience)),
                                  ("ssh -t HOST CMD", lambda: ssh_round(env, server, prefix, True, args.patience))):
                for failure, seconds in measure().items():
                    results.setdefault(name, {}).setdefault(failure, []).append(seconds)
            print(f"round {round_number + 1} of {args.rounds} done", file=sys.stderr)

    def cell(values: list[float | None]) -> str:
        if any(value is None for value in values):
            stopped = [v for v in values if v is not None]
            return f"still running after {args.patience:g} s ({len(values) - len(stopped)} of {len(values)})"
        numbers = [v for v in values if v is not None]
        return f"{statistics.median(numbers):.2f} s ({min(numbers):.2f}-{max(numbers):.2f})"

    print(f"seconds until the remote process is gone, median (min-max) of {args.rounds} rounds\n")
    print(f"| failure | {' | '.join(results)} |")
    print(f"|---|{'---|' * len(results)}")
    for failure in FAILURES:
        print(f"| {failure} | {' | '.join(cell(results[name][failure]) for name in results)} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
