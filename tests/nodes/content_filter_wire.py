"""Bytes on the wire with and without a content filter, run inside a network namespace of its own
(``unshare -n``), so that the loopback interface carries nothing but this graph: a publisher of
RATE Hz messages of SIZE bytes (content_filter_node.py), then ``roc topic bw`` on it for WINDOW
seconds unfiltered, with a filter the middleware evaluates, and with the same filter evaluated by roc
(ROC_MIDDLEWARE_CONTENT_FILTER=0). Fast DDS is told to use UDP only (no shared memory), so every
byte it sends crosses the loopback interface. Prints one JSON object: per run, the bytes the
interface carried per second and per message published meanwhile (a loaded machine publishes less
than RATE), and what roc topic bw measured.

    unshare -n python content_filter_wire.py RATE SIZE WINDOW ROC"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
FILTER = ["--content-filter", "data LIKE %0", "--content-filter-params", "3%"]


def loopback_bytes() -> int:
    """Bytes the loopback interface of this process's network namespace sent (/proc/self/net/dev;
    /sys/class/net shows the namespace that mounted /sys)."""
    for line in Path("/proc/self/net/dev").read_text().splitlines():
        name, _, counters = line.partition(":")
        if name.strip() == "lo":
            return int(counters.split()[8])  # after 8 receive counters, the bytes sent
    raise SystemExit("no loopback interface in /proc/self/net/dev")


def measure(roc: str, window: float, extra: list[str], env: dict[str, str], rate: str, size: str) -> dict:
    """A fresh publisher (no reader of an earlier run still matched) and roc topic bw for ``window``
    seconds from its first report: the loopback's bytes per second and bw's last report."""
    counter = Path(tempfile.mkdtemp()) / "published"
    publisher = subprocess.Popen([sys.executable, str(HERE / "content_filter_node.py"), rate, size, str(counter)],
                                 env=env, stdout=subprocess.PIPE, text=True)

    def published() -> int:
        return int(counter.read_text() or 0)

    bw = None
    try:
        assert publisher.stdout.readline().strip() == "ready"
        bw = subprocess.Popen([roc, "topic", "bw", "/numbers", "--format", "json", "--no-daemon", "--spin-time", "1",
                               *extra], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        first = bw.stdout.readline()  # the subscription is matched and messages flow
        if not first:
            raise SystemExit(f"roc topic bw ended: {bw.stderr.read()}")
        start, started, first_count = loopback_bytes(), time.monotonic(), published()
        last = first
        while time.monotonic() - started < window:
            last = bw.stdout.readline()
        sent, messages = loopback_bytes() - start, published() - first_count
        wire = sent / (time.monotonic() - started)
    finally:
        stderr = ""
        if bw is not None:
            bw.send_signal(signal.SIGINT)
            stderr = bw.communicate(timeout=20)[1]
        publisher.send_signal(signal.SIGINT)
        publisher.wait(timeout=20)
    return {"wire_bytes_per_second": wire, "wire_bytes_per_message": sent / max(messages, 1), "published": messages,
            "bw": json.loads(last), "stderr": stderr}


def main() -> None:
    rate, size, window, roc = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
    for command in (["ip", "link", "set", "lo", "up"], ["ip", "link", "set", "lo", "multicast", "on"],
                    ["ip", "route", "add", "224.0.0.0/4", "dev", "lo"]):
        subprocess.run(command, check=True)
    env = {**os.environ, "FASTDDS_BUILTIN_TRANSPORTS": "UDPv4"}
    results = {"unfiltered": measure(roc, window, [], env, rate, size),
               "middleware": measure(roc, window, FILTER, env, rate, size),
               "roc": measure(roc, window, FILTER, {**env, "ROC_MIDDLEWARE_CONTENT_FILTER": "0"}, rate, size)}
    print(json.dumps(results))


if __name__ == "__main__":
    main()
