"""What the bridge tests share: a running ``roc bridge`` read line by line and stopped as Ctrl+C
would, and nodes on both sides that talk and listen, to check that each message crosses exactly once."""

from __future__ import annotations

import signal
import subprocess
import time

from helpers.build import BIN, stop_process
from helpers.graph import read_line


def start_bridge(*args: str, env: dict[str, str]) -> subprocess.Popen:
    """A running ``roc bridge``; read its stdout with ``bridge_line``."""
    return subprocess.Popen([str(BIN / "roc"), "bridge", *args], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def bridge_line(process: subprocess.Popen, deadline: float) -> str:
    """The bridge's next stdout line; fails the test if none comes before ``deadline``."""
    line = read_line(process, deadline - time.monotonic())
    if not line:
        raise AssertionError("roc bridge ended" if line == "" else "roc bridge printed nothing more in time")
    return line


def stop_bridge(process: subprocess.Popen) -> int:
    process.send_signal(signal.SIGINT)
    try:
        return process.wait(timeout=15)
    finally:
        stop_process(process)


HEADER = "std_msgs/msg/Header"


def talker_and_listener(side: str) -> dict:
    """A node that publishes /chatter headers stamped at publication (each one different) with
    ``frame_id`` ``side``, and prints every /chatter message it receives."""
    return {"name": f"node_{side}", "publishers": [{"topic": "chatter", "type": HEADER, "values": {"frame_id": side},
                                                     "rate_hz": 20, "stamp_now": True}],
            "subscribers": [{"topic": "chatter", "type": HEADER, "print": True}]}


def hear_the_other_side(nodes: list[subprocess.Popen], seconds: float = 30) -> list[list[str]]:
    """The messages each ``talker_and_listener`` node ("a", then "b") printed, read until each has
    more than 20 from the other side's talker (a node may match the bridge's writer seconds late)."""
    deadline = time.monotonic() + seconds
    heard: list[list[str]] = []
    for node, side, other in zip(nodes, ("a", "b"), ("b", "a")):
        messages: list[str] = []
        while sum(f"frame_id='{other}'" in message for message in messages) <= 20:
            line = read_line(node, deadline - time.monotonic())
            assert line, f"side {side} got {len(messages)} messages in {seconds} s, too few from side {other}"
            if line.startswith("{"):
                messages.append(line)
        heard.append(messages)
    return heard


def assert_each_arrived_once(nodes: list[subprocess.Popen], heard: list[list[str]]) -> None:
    """With the nodes stopped, the rest of what they printed: no message arrived twice (a loop would
    bring each one back again and again)."""
    for node, messages in zip(nodes, heard):
        while line := read_line(node, 10):
            if line.startswith("{"):
                messages.append(line)
        assert len(messages) == len(set(messages)), "a message arrived twice"
