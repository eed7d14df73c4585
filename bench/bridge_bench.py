#!/usr/bin/env python3
"""Loss and added latency through ``roc bridge``: per rate (1 kHz, 5 kHz), a paced publisher
(bench/paced_publisher.py, each message stamped with its publication time) in ROS domain 95 for
``--seconds``, a minimal rclpy subscriber (bench/counting_subscriber.py, on the C++ EventsExecutor)
in domain 95 itself (the direct subscription) and one in domain 96 behind ``roc bridge --from-domain 95 --to-domain 96``, all
at once. Prints messages received and lost by each, and the latency at the median and the 99th
percentile, direct and bridged, and what the bridge adds. Then the same through the Zenoh link: two
``roc bridge`` processes joined by Zenoh on localhost TCP (``--zenoh-listen`` in domain 95,
``--zenoh-connect`` in domain 96).

    python bench/bridge_bench.py [--rates 1000 5000] [--seconds 5] [--links domain zenoh]

Localhost discovery. Target (issue 15): no loss at 1 kHz, under 1 % at 5 kHz, added median latency
under 1 ms. Every process shares the machine's cores (2 here), the publisher's and subscribers' too, so
each run also prints the CPU each process used while the publisher sent (percent of one core) and their
sum: latency through the bridges grows as the cores run out. Every process runs at the same priority
(the publisher is not ``steady``: see paced_publisher.py).
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import psutil

HERE = Path(__file__).resolve().parent
ROC = Path(sys.executable).parent / "roc"
SOURCE, TARGET = 95, 96
ZENOH_PORT = 7495
WAIT_SECONDS = 6.0  # the publisher waits this long: the bridge finds it, the subscribers match


def _env(domain: int) -> dict[str, str]:
    return {**os.environ, "ROS_DOMAIN_ID": str(domain), "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}


def _start(command: list, domain: int, out: Path) -> subprocess.Popen:
    return subprocess.Popen([str(c) for c in command], env=_env(domain), stdout=out.open("w"),
                            stderr=subprocess.DEVNULL)


def _stop(process: subprocess.Popen) -> None:
    process.send_signal(signal.SIGINT)
    try:
        process.wait(timeout=15)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()


def _result(path: Path) -> dict:
    lines = [line for line in path.read_text().splitlines() if line.startswith("{")]
    return json.loads(lines[-1]) if lines else {"count": 0}


def _bridges(topic: str, zenoh: bool) -> list[tuple[list, int]]:
    """The bridge processes' commands and ROS domains."""
    if not zenoh:
        return [([ROC, "bridge", "--from-domain", SOURCE, "--to-domain", TARGET, topic], SOURCE)]
    endpoint = f"tcp/127.0.0.1:{ZENOH_PORT}"
    return [([ROC, "bridge", "--zenoh-listen", endpoint, "--domain", SOURCE, topic], SOURCE),
            ([ROC, "bridge", "--zenoh-connect", endpoint, "--domain", TARGET, topic], TARGET)]


def _cpu_seconds(processes: dict[str, subprocess.Popen]) -> dict[str, float]:
    """CPU seconds each process (all its threads) has used so far."""
    used = {}
    for name, process in processes.items():
        try:
            times = psutil.Process(process.pid).cpu_times()
            used[name] = times.user + times.system
        except psutil.NoSuchProcess:
            pass
    return used


def _cpu_while_sending(processes: dict[str, subprocess.Popen], seconds: float) -> dict[str, float]:
    """Percent of one core each process used over the middle of the publisher's sending (``seconds``
    long, starting WAIT_SECONDS after it was started, which is now)."""
    time.sleep(WAIT_SECONDS + 0.1 * seconds)
    before, start = _cpu_seconds(processes), time.monotonic()
    time.sleep(0.8 * seconds)
    after, elapsed = _cpu_seconds(processes), time.monotonic() - start
    return {name: 100 * (after[name] - before[name]) / elapsed for name in after if name in before}


def rate_run(rate: float, seconds: float, work: Path, zenoh: bool = False) -> dict:
    topic = f"/bridged_{int(rate)}"
    subscriber = [sys.executable, HERE / "counting_subscriber.py", topic, "latency", "events"]
    outputs = {name: work / f"{name}_{int(rate)}.txt" for name in ("publisher", "direct", "bridged")}
    processes = {f"bridge{i}": _start(command, domain, work / f"bridge{i}_{int(rate)}.txt")
                 for i, (command, domain) in enumerate(_bridges(topic, zenoh))}
    processes.update(direct=_start(subscriber, SOURCE, outputs["direct"]),
                     bridged=_start(subscriber, TARGET, outputs["bridged"]))
    publisher = _start([sys.executable, HERE / "paced_publisher.py", topic, rate, seconds, WAIT_SECONDS, "stamped"],
                       SOURCE, outputs["publisher"])
    try:
        cpu = _cpu_while_sending({"publisher": publisher, **processes}, seconds)
        publisher.wait(timeout=WAIT_SECONDS + seconds + 60)
        time.sleep(1.0)  # the last messages drain
    finally:
        for process in (publisher, *processes.values()):
            _stop(process)
    return {"cpu": cpu, **{name: _result(outputs[name]) for name in ("publisher", "direct", "bridged")}}


LINKS = {"domain": "roc bridge (domain to domain)", "zenoh": "Zenoh (two roc bridge processes)"}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rates", type=float, nargs="+", default=[1000, 5000])
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--links", nargs="+", choices=sorted(LINKS), default=list(LINKS))
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    print(f"{'link':>6} {'rate':>6} {'sent':>7} | {'direct':>7} {'lost':>6} {'med ms':>7} {'p99 ms':>7} | "
          f"{'bridged':>7} {'lost':>6} {'med ms':>7} {'p99 ms':>7} | {'added med':>9} {'added p99':>9}")
    verdicts = []
    for link in args.links:
        for rate in args.rates:
            with tempfile.TemporaryDirectory(prefix="roc-bridge-bench-") as work:
                result = rate_run(rate, args.seconds, Path(work), link == "zenoh")
            sent = result["publisher"].get("count", 0)
            direct, bridged = result["direct"], result["bridged"]
            loss = (sent - bridged["count"]) / sent if sent else 1.0
            added = (bridged.get("median_ms", float("nan")) - direct.get("median_ms", float("nan")),
                     bridged.get("p99_ms", float("nan")) - direct.get("p99_ms", float("nan")))
            print(f"{link:>6} {rate:>6.0f} {sent:>7} | {direct['count']:>7} {sent - direct['count']:>6} "
                  f"{direct.get('median_ms', float('nan')):>7.2f} {direct.get('p99_ms', float('nan')):>7.2f} | "
                  f"{bridged['count']:>7} {sent - bridged['count']:>6} {bridged.get('median_ms', float('nan')):>7.2f} "
                  f"{bridged.get('p99_ms', float('nan')):>7.2f} | {added[0]:>9.2f} {added[1]:>9.2f}")
            cpu = result["cpu"]
            print(f"{'':>6} {'':>6} CPU while sending, % of one core: "
                  + ", ".join(f"{name} {percent:.0f}" for name, percent in cpu.items())
                  + f"; all {sum(cpu.values()):.0f} of {100 * psutil.cpu_count():.0f}")
            allowed = 0.0 if rate <= 1000 else 0.01
            verdicts.append(f"{LINKS[link]}, {rate:.0f} Hz: loss {loss:.2%} (target {'none' if not allowed else 'under 1%'}), "
                            f"added median {added[0]:.2f} ms (target under 1 ms): "
                            f"{'met' if loss <= allowed and added[0] < 1.0 else 'NOT met'}")
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    print("\n".join(verdicts))
    return 0


if __name__ == "__main__":
    sys.exit(main())
