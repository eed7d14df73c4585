#!/usr/bin/env python3
"""``roc bag`` against a minimal rclpy control, in one run (ROS domain 97, localhost discovery):

1. record: a paced publisher sends for ``--seconds`` (5 kHz small std_msgs/String, then 30 Hz
   sensor_msgs/Image of 2.1 MB); ``roc bag record`` and bench/counting_subscriber.py (rclpy's C++
   EventsExecutor) listen at once. Prints what each got, the losses roc reported (publisher sequence
   numbers), and the CPU each used per message (its process's user+system time while recording).
2. info: ``roc bag info`` on a 1 GB MCAP file roc wrote (bare file: from its summary; and its bag
   directory: from metadata.yaml), the median of 5 runs, the whole process.
3. play: a bag of a 1 kHz topic (exactly 1 ms apart, ``--seconds`` long) played by ``roc bag play``
   while ``roc bag record`` records it again; the inter-message timing error is each interval
   between two receptions (the second bag's times, so the middleware's delivery jitter counts) minus
   the recorded interval, as the median and 99th percentile of its absolute value; also each
   message's reception against its recorded time less the median delay. The control counts the
   same topic.

    python bench/bag_bench.py [--seconds 10] [--parts record info play]

Targets (issue 30): roc records at least as many as the control receives and reports every loss;
info on 1 GB in < 0.5 s; play timing error median < 0.2 ms, p99 < 2 ms. The machine is shared (2
cores): run on a quiet machine and read the numbers with the load printed beside them.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import statistics
import subprocess
import sys
import time
from pathlib import Path

import psutil

HERE = Path(__file__).resolve().parent
ROC = Path(sys.executable).parent / "roc"
WORK = HERE / ".work" / "bag"
DOMAIN = "97"
WAIT_SECONDS = 5.0  # the publisher waits this long: recorder and control subscribe


def _env() -> dict[str, str]:
    return {**os.environ, "ROS_DOMAIN_ID": DOMAIN, "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}


def _start(command: list, out: Path | None = None) -> subprocess.Popen:
    return subprocess.Popen([str(c) for c in command], env=_env(), text=True,
                            stdout=out.open("w") if out else subprocess.PIPE, stderr=subprocess.DEVNULL)


def _interrupt(process: subprocess.Popen) -> str:
    process.send_signal(signal.SIGINT)
    output, _ = process.communicate(timeout=60)
    return output or ""


def _cpu(process: subprocess.Popen) -> float:
    times = psutil.Process(process.pid).cpu_times()
    return times.user + times.system


def _load() -> str:
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f}"


def record(name: str, publisher: list, topic: str, seconds: float, control_type: str) -> None:
    bag = WORK / name
    shutil.rmtree(bag, ignore_errors=True)
    recorder = _start([ROC, "bag", "record", topic, "-o", bag])
    control = _start([sys.executable, HERE / "counting_subscriber.py", topic, "events", f"type={control_type}"])
    source = _start([sys.executable, *publisher])
    time.sleep(WAIT_SECONDS - 1)
    cpu_start = {"roc": _cpu(recorder), "control": _cpu(control)}
    sent = json.loads(source.communicate(timeout=seconds + 60)[0])
    time.sleep(1.0)  # the last messages arrive
    cpu = {"roc": _cpu(recorder) - cpu_start["roc"], "control": _cpu(control) - cpu_start["control"]}
    summary = _interrupt(recorder)
    counted = json.loads(_interrupt(control).strip().splitlines()[-1])["count"]
    written = next(int(line.split()[1]) for line in summary.splitlines() if line.startswith("Recorded "))
    lost = next(line for line in summary.splitlines() if line.startswith("Lost messages"))
    print(f"  {name}: sent {sent['count']} ({sent['rate']:.0f} Hz); control received {counted}; "
          f"roc wrote {written} ({written / max(counted, 1):.3f}x the control); roc: {lost}")
    print(f"    CPU per message: roc {1e6 * cpu['roc'] / max(written, 1):.1f} us, "
          f"control {1e6 * cpu['control'] / max(counted, 1):.1f} us; {_load()}")


def info(gigabytes: float) -> None:
    sys.path.insert(0, str(HERE.parent))
    from roc.bag.definitions import definition
    from roc.bag.metadata import Topic
    from roc.bag.writer import BagWriter, WriteOptions

    bag = WORK / f"big_{gigabytes:g}gb"
    if not (bag / "metadata.yaml").exists():
        shutil.rmtree(bag, ignore_errors=True)
        writer = BagWriter(bag, WriteOptions())
        for index in range(4):
            writer.add_topic(Topic(f"/t{index}", "std_msgs/msg/String"), definition("std_msgs/msg/String"))
        payload = b"\x00\x01\x00\x00" + bytes(256 * 1024)
        count = int(gigabytes * 2**30 / len(payload))
        for index in range(count):
            writer.write(f"/t{index % 4}", payload, 1_700_000_000_000_000_000 + index * 1_000_000)
        writer.close()
    size = sum(f.stat().st_size for f in bag.iterdir()) / 2**30
    for target in (bag / f"{bag.name}_0.mcap", bag):
        runs = []
        for _ in range(5):
            started = time.perf_counter()
            subprocess.run([ROC, "bag", "info", target], check=True, capture_output=True)
            runs.append(time.perf_counter() - started)
        print(f"  info {target.name} ({size:.2f} GiB): median {statistics.median(runs):.3f} s, "
              f"min {min(runs):.3f} s over 5 runs; {_load()}")


def play(seconds: float) -> None:
    sys.path.insert(0, str(HERE.parent))
    from rclpy.serialization import serialize_message
    from std_msgs.msg import String

    from roc.bag.definitions import definition
    from roc.bag.metadata import Topic
    from roc.bag.qos import default_profile
    from roc.bag.reader import Bag
    from roc.bag.writer import BagWriter, WriteOptions

    source, again = WORK / "tick", WORK / "tick_again"
    shutil.rmtree(source, ignore_errors=True)
    shutil.rmtree(again, ignore_errors=True)
    writer = BagWriter(source, WriteOptions())
    writer.add_topic(Topic("/tick", "std_msgs/msg/String", "cdr", [default_profile()]),
                     definition("std_msgs/msg/String"))
    start = 1_700_000_000_000_000_000
    count = int(seconds * 1000)
    for index in range(count):
        writer.write("/tick", serialize_message(String(data=str(index))), start + index * 1_000_000)
    writer.close()
    recorder = _start([ROC, "bag", "record", "/tick", "-o", again])
    control = _start([sys.executable, HERE / "counting_subscriber.py", "/tick", "events"])
    player = _start([ROC, "bag", "play", "--delay", str(WAIT_SECONDS), "--wait-for-all-acked", "5000",
                     "--disable-keyboard-controls", source])
    played = player.communicate(timeout=seconds + 60)[0]
    time.sleep(0.5)
    summary = _interrupt(recorder)
    counted = json.loads(_interrupt(control).strip().splitlines()[-1])["count"]
    with Bag(again) as bag:
        received = {int(m.data[8:8 + int.from_bytes(m.data[4:8], "little") - 1]): m.log_time
                    for m in bag.messages()}
    order = sorted(received)
    # inter-message error: each reception interval minus the recorded interval (1 ms a message)
    errors = sorted(abs((received[b] - received[a]) - (b - a) * 1_000_000) / 1e6 for a, b in zip(order, order[1:]))
    p99 = errors[int(len(errors) * 0.99)]
    # and each message's reception against its recorded time, less the typical (median) delay
    delays = [received[i] - (start + i * 1_000_000) for i in order]
    typical = statistics.median(delays)
    drift = sorted(abs(d - typical) / 1e6 for d in delays)
    print(f"  play 1 kHz for {seconds:.0f} s: played {count}; control received {counted}; roc re-recorded "
          f"{len(received)} ({summary.strip().splitlines()[-1]})")
    print(f"    inter-message timing error (reception intervals vs recorded intervals): median "
          f"{statistics.median(errors):.3f} ms, p99 {p99:.3f} ms, max {errors[-1]:.3f} ms; {_load()}")
    print(f"    each message against its recorded time (less the median delay): median "
          f"{statistics.median(drift):.3f} ms, p99 {drift[int(len(drift) * 0.99)]:.3f} ms, max {drift[-1]:.3f} ms")
    print(f"    player's own report: {played.strip().splitlines()[-1]}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--gigabytes", type=float, default=1.0)
    parser.add_argument("--parts", nargs="+", default=["record", "info", "play"], choices=["record", "info", "play"])
    args = parser.parse_args()
    WORK.mkdir(parents=True, exist_ok=True)
    print(f"bag_bench: {os.cpu_count()} cores, {_load()}")
    if "record" in args.parts:
        print("record (roc bag record vs a minimal rclpy subscriber):")
        record("small_5khz", [HERE / "paced_publisher.py", "/small", "5000", args.seconds, WAIT_SECONDS], "/small",
               args.seconds, "std_msgs/msg/String")
        record("images_30hz", [HERE / "image_publisher.py", "/image", "30", args.seconds, WAIT_SECONDS], "/image",
               args.seconds, "sensor_msgs/msg/Image")
    if "info" in args.parts:
        print("info:")
        info(args.gigabytes)
    if "play" in args.parts:
        print("play:")
        play(args.seconds)


if __name__ == "__main__":
    main()
