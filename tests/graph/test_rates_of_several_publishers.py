"""Issue 51: a topic with several publishers reads their summed rate from its first report, in
``roc topic hz`` and in the first screen's rates (roc.tui.model.Rates on the daemon's ``stats`` stream):
two real rclpy publishers at 2 Hz each, 0.1 s apart. Their messages counted over the time they span
read 5 or 3.3 Hz in the first second."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from helpers.build import BIN, stop_process
from helpers.graph import graph_env, read_line, stop_all, stop_daemon
from helpers.rmw import CYCLONEDDS, suite_middleware

from roc.middleware import process_environment

pytestmark = [pytest.mark.slow, pytest.mark.rmw]

SLOT = 63
PUBLISHER = r'''
import sys, time
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.qos import QoSProfile
from std_msgs.msg import String

phase, period = float(sys.argv[1]), 0.5
rclpy.init()
node = rclpy.create_node(sys.argv[2])
publisher = node.create_publisher(String, "/pair", QoSProfile(depth=10))
time.sleep((phase - time.time()) % period)  # the timer starts at this phase of the clock's half seconds
node.create_timer(period, lambda: publisher.publish(String(data="x")))
print("ready", flush=True)
try:
    rclpy.spin(node)
except (KeyboardInterrupt, ExternalShutdownException):
    pass
'''
RATES = r'''
import contextlib
from roc.ros.client import stream
from roc.tui.model import Rates

rates = Rates()
with contextlib.closing(stream("stats", {"topics": ["/pair"], "wait": 10})) as events:
    for event in events:
        if event["event"] == "batch":
            rates.add(event)
            if (rate := rates.rate("/pair")) is not None:
                print(rate)
                break
'''


def test_two_publishers_read_their_sum_in_the_first_report(tmp_path) -> None:
    env = graph_env(SLOT, tmp_path)
    publishers = [subprocess.Popen([sys.executable, "-c", PUBLISHER, str(phase), name], env=process_environment(env),
                                   stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
                  for phase, name in ((0.0, "first_publisher"), (0.1, "second_publisher"))]
    try:
        for publisher in publishers:
            assert read_line(publisher, 30) == "ready\n"
        hz = subprocess.Popen([str(BIN / "roc"), "topic", "hz", "/pair", "--format", "json"], env=env,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            first = read_line(hz, 30)
        finally:
            stop_process(hz)
        assert first, f"roc topic hz printed nothing: {hz.stderr.read()}"
        report = json.loads(first)
        lost = None if suite_middleware() == CYCLONEDDS else 0  # unknown: Cyclone DDS gives no sequence numbers
        assert (report["rate"], report["lost"]) == (pytest.approx(4.0, rel=0.1), lost), report
        assert report["window"] >= 3

        rates = subprocess.run([sys.executable, "-c", RATES], env=env, capture_output=True, text=True, timeout=60)
        assert rates.returncode == 0, rates.stderr
        assert float(rates.stdout) == pytest.approx(4.0, rel=0.1)
    finally:
        stop_daemon(env)
        stop_all(publishers)
