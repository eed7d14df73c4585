"""roc.ros.raw_subscription's Receiver and the echo stream on it, in a real rclpy process: a reader
busy elsewhere loses nothing a shallow history would have dropped, every message comes with its
publisher's gid and sequence number, closing leaves no subscription, and losses are counted per
publisher (two publishers on one topic are not a loss)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.graph import graph_env

pytestmark = pytest.mark.slow

SCRIPT = r'''
import json, time
from rclpy.qos import QoSProfile
from rclpy.serialization import deserialize_message
from std_msgs.msg import String
from roc.ros.dataplane import echo
from roc.ros.graph import Graph
from roc.ros.raw_subscription import Receiver

def matched(*publishers):
    deadline = time.monotonic() + 10
    while any(p.get_subscription_count() < 1 for p in publishers) and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(0.2)  # and the subscription has matched them

graph = Graph()
burst = graph.node.create_publisher(String, "/burst", QoSProfile(depth=1000))
receiver = Receiver(graph.node)
receiver.subscribe("burst", String, "/burst", QoSProfile(depth=10))
while not receiver.batch(0.01):  # until the subscription has matched the publisher
    burst.publish(String(data="-1"))
time.sleep(0.1)
receiver.batch(0.01)
for number in range(500):
    burst.publish(String(data=str(number)))
    time.sleep(0.001)
time.sleep(1.0)  # the reader was busy elsewhere all along; a history of 10 alone would keep the last 10
taken = []
while batch := receiver.batch(0.5):
    taken += batch
receiver.close()
time.sleep(0.2)
left = len(graph.node.get_subscriptions_info_by_topic("/burst"))

first, second = (graph.node.create_publisher(String, "/two", QoSProfile(depth=100)) for _ in range(2))
events = echo(graph, {"topic": "/two", "type": "std_msgs/msg/String"})
while next(events)["event"] != "subscribed":
    pass
matched(first, second)
for publisher, count in ((first, 5), (second, 1), (first, 5)):
    for _ in range(count):
        publisher.publish(String(data="x"))
messages = []
while len(messages) < 11:
    event = next(events)
    messages += event.get("messages", [])
events.close()
print(json.dumps({
    "data": [int(deserialize_message(data, String).data) for _, data, _ in taken],
    "keys": sorted({key for key, _, _ in taken}),
    "sequences": [info["publication_sequence_number"] for _, _, info in taken],
    "gids": sorted({info["gid"] for _, _, info in taken}),
    "left": left,
    "echo_lost": [message["lost"] for message in messages],
    "echo_info": sorted(messages[0]["info"]),
}))
graph.close()
'''


def test_receiver_takes_everything_and_echo_counts_losses_per_publisher(tmp_path: Path) -> None:
    env = graph_env(15, tmp_path)
    result = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    found = json.loads(result.stdout.splitlines()[-1])
    assert found["data"] == list(range(500))
    assert found["keys"] == ["burst"]
    assert found["sequences"] == list(range(found["sequences"][0], found["sequences"][0] + 500))
    assert len(found["gids"]) == 1 and len(found["gids"][0].split(".")) == 16
    assert found["left"] == 0
    assert found["echo_lost"] == [0] * 11
    # as rclpy gives it, without the reception sequence number Fast DDS does not keep
    assert found["echo_info"] == ["publication_sequence_number", "received_timestamp", "source_timestamp"]
