"""roc bag record --repeat-transient-local on a live graph: a recording of /tf and /tf_static split
every second, each of whose files, played alone, gives a tf static listener (tests/nodes/tf_node.py: an
rclpy subscription to /tf_static, transient local as tf2's) both static frames."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from helpers.build import BIN, NODES, stop_process
from helpers.graph import graph_env, read_line, stop_daemon, wait_for, with_tf2_msgs

pytestmark = pytest.mark.slow
TF_NODE = NODES / "tf_node.py"
STATIC = {("map", "odom"), ("base_link", "laser")}  # what tf_node.py publish latches on /tf_static


def node(mode: str, env: dict[str, str]) -> subprocess.Popen:
    process = subprocess.Popen([sys.executable, str(TF_NODE), mode], env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.DEVNULL, text=True)
    assert read_line(process, 60) == "ready\n"
    return process


@pytest.fixture(scope="module")
def recording(tmp_path_factory) -> Iterator[tuple[Path, dict[str, str]]]:
    """A bag of /tf and /tf_static in files of one second each, and the environment it was made in."""
    env = with_tf2_msgs(graph_env(58, tmp_path_factory.mktemp("runtime")))
    bag = tmp_path_factory.mktemp("record") / "tf"
    publisher = node("publish", env)
    recorder = subprocess.Popen([str(BIN / "roc"), "bag", "record", "-o", str(bag), "/tf", "/tf_static",
                                 "--max-bag-duration", "1", "--repeat-transient-local", "--disable-keyboard-controls"],
                                env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        subscribed = [read_line(recorder, 30) for _ in range(3)]
        assert "Subscribed to topic '/tf_static' (repeat-transient-local, depth=1)\n" in subscribed, subscribed
        wait_for(lambda: (bag / "tf_3.mcap").exists(), timeout=30)  # three whole files, a fourth begun
        recorder.send_signal(signal.SIGINT)
        assert recorder.wait(timeout=30) == 0, recorder.stderr.read()
    finally:
        stop_process(recorder)
        stop_process(publisher)
    try:
        yield bag, env
    finally:
        stop_daemon(env)


def heard_static(bag_file: Path, env: dict[str, str]) -> set[tuple[str, str]]:
    """The static transforms a fresh listener hears while ``bag_file`` alone plays."""
    listener = node("listen", env)
    heard: set[tuple[str, str]] = set()
    try:
        # the file's tf_static, played once the listener is matched, and the player ends only once the
        # listener has it: the writer may see the match before the listener does, and then the listener
        # can take the message only from a writer that still exists (rosbag2's --wait-for-all-acked)
        player = subprocess.run([str(BIN / "roc"), "bag", "play", str(bag_file), "--topics", "/tf_static",
                                 "--wait-for-subscribers", "--wait-for-all-acked", "10000",
                                 "--disable-keyboard-controls"],
                                env=env, capture_output=True, text=True, timeout=60)
        assert player.returncode == 0, player.stderr
        while heard != STATIC and (line := read_line(listener, 10)):
            transform = json.loads(line)
            heard.add((transform["parent"], transform["child"]))
        return heard
    finally:
        stop_process(listener)


def test_each_split_file_plays_alone_with_the_static_frames(recording):
    bag, env = recording
    files = sorted(bag.glob("tf_*.mcap"), key=lambda path: int(path.stem.split("_")[1]))
    assert len(files) >= 4
    for bag_file in files[1:3]:  # split files: without the repeat these hold no /tf_static at all
        assert heard_static(bag_file, env) == STATIC, bag_file.name


def test_the_whole_recording_plays_each_static_message_once(recording):
    """The copies at the start of each file are for a file played alone: played whole, the bag publishes
    /tf_static as it was recorded (ros2 bag play publishes every copy)."""
    from roc.bag.reader import Bag, repeated_copies

    bag, env = recording
    with Bag(bag) as opened:
        repeated = repeated_copies(opened)["/tf_static"]
        recorded = {topic.name: count for topic, count in opened.metadata.topics}["/tf_static"]
    assert repeated >= 3  # each file after the first begins with a copy
    player = subprocess.run([str(BIN / "roc"), "bag", "play", str(bag), "--topics", "/tf_static",
                             "--disable-keyboard-controls"], env=env, capture_output=True, text=True, timeout=60)
    assert player.returncode == 0, player.stderr
    played = recorded - repeated
    assert f"Played {played} message{'s' if played > 1 else ''} on 1 topic" in player.stdout, player.stdout
    assert f"Not played again: {repeated} of the transient local messages" in player.stdout, player.stdout
