"""roc bag record and play on a live graph (real rclpy nodes in subprocesses): recordings read back
byte for byte, record -> play -> record round trips of every test_msgs type, topics found late, QoS
adapted, services, keyboard control, crashes (SIGKILL, a full disk) and Ctrl+C."""

from __future__ import annotations

import os
import pty
import re
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml
from helpers.bag import BAG_ONLY_TYPE, TEST_MSGS, filled, load, write_bag_only_bag
from helpers.build import BIN, NODES, stop_process
from helpers.graph import graph_env, read_line, start_nodes

from roc.bag.reader import Bag

pytestmark = pytest.mark.slow
NODE = NODES / "bag_node.py"
TYPES = [f"test_msgs/msg/{name}" for name in TEST_MSGS]


def start(args: list[str], env: dict, cwd: Path, **kwargs) -> subprocess.Popen:
    return subprocess.Popen(args, env=env, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            **kwargs)


def roc_process(*args: str, env: dict, cwd: Path, **kwargs) -> subprocess.Popen:
    return start([str(BIN / "roc"), *args], env, cwd, **kwargs)


def wait_for_line(process: subprocess.Popen, wanted: str, timeout: float = 30) -> list[str]:
    """Lines of stdout up to one containing ``wanted``; fails if the process ends or stays silent."""
    seen = []
    deadline = time.monotonic() + timeout
    while True:
        line = read_line(process, max(0.1, deadline - time.monotonic()))
        assert line, f"no line with {wanted!r} (process ended or timed out); saw {seen}"
        seen.append(line)
        if wanted in line:
            return seen


def wait_subscribed(recorder: subprocess.Popen, topics: list[str], timeout: float = 30) -> None:
    pending = {f"Subscribed to topic '{t}'" for t in topics}
    deadline = time.monotonic() + timeout
    while pending:
        line = read_line(recorder, max(0.1, deadline - time.monotonic()))
        assert line, f"recorder never subscribed to {pending}"
        pending.discard(line.strip())


def interrupt(process: subprocess.Popen, timeout: float = 30) -> str:
    """Ctrl+C a recorder or player; returns the rest of its stdout."""
    process.send_signal(signal.SIGINT)
    rest = []
    while (line := read_line(process, timeout)) not in ("", None):
        rest.append(line)
    assert process.wait(timeout=timeout) == 0, process.stderr.read()
    return "".join(rest)


def messages(bag_path: Path) -> dict[str, list[bytes]]:
    found: dict[str, list[bytes]] = {}
    with Bag(bag_path) as bag:
        for message in bag.messages():
            found.setdefault(message.topic, []).append(message.data)
    return found


def play_when_recorder_listens(bag: Path, recorder: subprocess.Popen, topics: list[str], env: dict, cwd: Path,
                               *options: str) -> str:
    """Play ``bag`` started paused on a terminal, press space once the recorder subscribed to every
    topic (and, --wait-for-subscribers, the player matched each subscription), and return the
    player's output (stdout, then stderr) when it ends."""
    controller, terminal = pty.openpty()
    player = start([str(BIN / "roc"), "bag", "play", "-p", "--wait-for-subscribers", "--wait-for-all-acked", "10000",
                    *options, str(bag)], env, cwd, stdin=terminal)
    os.close(terminal)
    try:
        wait_for_line(player, "Paused")
        wait_subscribed(recorder, topics)
        os.write(controller, b" ")
        output = []
        while (line := read_line(player, 60)) not in ("", None):
            output.append(line)
        errors = player.stderr.read()
        assert player.wait(timeout=60) == 0, errors
        return "".join(output) + errors
    finally:
        os.close(controller)
        stop_process(player)


@pytest.mark.distro
def test_record_play_record_round_trip_of_every_test_msgs_type(tmp_path):
    env = graph_env(32, tmp_path)
    topics = [f"/{name.lower()}" for name in TEST_MSGS]
    first = roc_process("bag", "record", *topics, "-o", "first", env=env, cwd=tmp_path)
    node = start([sys.executable, str(NODE), "publish", "5", "20", *TYPES], env, tmp_path)
    try:
        wait_subscribed(first, topics)
        wait_for_line(node, "done", timeout=60)
        summary = interrupt(first)
    finally:
        stop_process(node)
        stop_process(first)
    assert "Lost messages: 0" in summary
    from rclpy.serialization import deserialize_message

    recorded = messages(tmp_path / "first")
    assert {topic: [deserialize_message(data, load(f"test_msgs/msg/{n}")) for data in recorded[topic]]
            for n in TEST_MSGS for topic in [f"/{n.lower()}"]} == {
        f"/{n.lower()}": [filled(load(f"test_msgs/msg/{n}"), seed) for seed in range(5)] for n in TEST_MSGS}

    second = roc_process("bag", "record", *topics, "-o", "second", "-s", "sqlite3", env=env, cwd=tmp_path)
    try:
        played = play_when_recorder_listens(tmp_path / "first", second, topics, env, tmp_path)
        assert f"Played {5 * len(TEST_MSGS)} messages on {len(TEST_MSGS)} topics" in played
        interrupt(second)
    finally:
        stop_process(second)
    assert messages(tmp_path / "second") == recorded  # byte-identical CDR, every type, in order
    with Bag(tmp_path / "second") as bag:
        assert bag.storage == "sqlite3" and all(t.offered_qos_profiles for t in bag.topics())


def test_late_topics_qos_and_selection(tmp_path):
    env = graph_env(33, tmp_path)
    recorder = roc_process("bag", "record", "-a", "-x", "ignored", "-o", "bag", env=env, cwd=tmp_path)
    nodes = []
    try:
        wait_for_line(recorder, "Listening for topics")
        nodes = start_nodes([{"name": "late", "publishers": [
            {"topic": "latched", "type": "std_msgs/msg/String", "durability": "transient_local", "depth": 1,
             "values": {"data": "kept"}},
            {"topic": "fast", "type": "std_msgs/msg/String", "reliability": "best_effort", "values": {"data": "f"},
             "rate_hz": 50},
            {"topic": "ignored_topic", "type": "std_msgs/msg/String", "values": {"data": "x"}, "rate_hz": 50},
            {"topic": "_hidden", "type": "std_msgs/msg/String", "values": {"data": "x"}, "rate_hz": 50}]}], env)
        wait_subscribed(recorder, ["/latched", "/fast"])
        with Bag(tmp_path / "bag") as partial:  # a recording in progress is readable
            assert partial.metadata_missing
        time.sleep(0.5)  # let /fast deliver a few messages
        interrupt(recorder)
    finally:
        for node in nodes:
            stop_process(node)
        stop_process(recorder)
    with Bag(tmp_path / "bag") as bag:
        names = {t.name for t in bag.topics()}
        assert {"/latched", "/fast"} <= names and not {"/ignored_topic", "/_hidden"} & names
        latched, fast = bag.metadata.topic("/latched"), bag.metadata.topic("/fast")
        assert latched.offered_qos_profiles[0]["durability"] == "transient_local"
        assert fast.offered_qos_profiles[0]["reliability"] == "best_effort"
        assert latched.type_description_hash.startswith("RIHS01_")
    found = messages(tmp_path / "bag")
    assert len(found["/latched"]) == 1 and found["/fast"]  # transient local: the message sent before


def test_services_are_recorded_with_request_and_response_counts(tmp_path):
    env = graph_env(34, tmp_path)
    node = start([sys.executable, str(NODE), "service", "4"], env, tmp_path, stdin=subprocess.PIPE)
    recorder = roc_process("bag", "record", "--all-services", "-o", "bag", env=env, cwd=tmp_path)
    try:
        assert read_line(node, 30).strip() == "ready"
        wait_subscribed(recorder, ["/toggle/_service_event"])
        node.stdin.write("go\n")
        node.stdin.flush()
        wait_for_line(node, "done")
        interrupt(recorder)
    finally:
        stop_process(node)
        stop_process(recorder)
    info = subprocess.run([str(BIN / "roc"), "bag", "info", "-v", str(tmp_path / "bag")], capture_output=True,
                          text=True, env=env)
    assert "Service:           1" in info.stdout
    assert ("Service: /toggle | Type: std_srvs/srv/SetBool | Request Count: 4 | Response Count: 4 | "
            "Serialization Format: cdr") in info.stdout
    plain = subprocess.run([str(BIN / "roc"), "bag", "info", str(tmp_path / "bag")], capture_output=True, text=True,
                           env=env)
    assert "Service: /toggle | Type: std_srvs/srv/SetBool | Event Count: 8 |" in plain.stdout  # received, sent


def _big_talker(env: dict) -> list[subprocess.Popen]:
    return start_nodes([{"name": "big", "publishers": [
        {"topic": "big", "type": "std_msgs/msg/String", "values": {"data": "x" * 20000}, "rate_hz": 100}]}], env)


def _wait_for_size(path: Path, size: int, timeout: float = 60) -> None:
    deadline = time.monotonic() + timeout
    while not (path.exists() and path.stat().st_size >= size):
        assert time.monotonic() < deadline, f"{path} never reached {size} bytes"
        time.sleep(0.1)


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_sigkill_loses_at_most_the_last_chunk_and_reindex_recovers(tmp_path, storage):
    env = graph_env(35, tmp_path)
    nodes = _big_talker(env)
    recorder = roc_process("bag", "record", "/big", "-o", "bag", "-s", storage, env=env, cwd=tmp_path)
    try:
        wait_subscribed(recorder, ["/big"])
        extension = ".mcap" if storage == "mcap" else ".db3"
        _wait_for_size(tmp_path / "bag" / f"bag_0{extension}", 3 * 768 * 1024)
        recorder.kill()
        recorder.wait()
    finally:
        for node in nodes:
            stop_process(node)
        stop_process(recorder)
    bag = tmp_path / "bag"
    assert not (bag / "metadata.yaml").exists()
    result = subprocess.run([str(BIN / "roc"), "bag", "reindex", str(bag)], capture_output=True, text=True, env=env)
    assert result.returncode == 0, result.stderr
    metadata = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    kept = metadata["message_count"]
    assert kept >= 2 * 768 * 1024 // 20000  # every chunk written whole before the kill
    from rosbags.rosbag2 import Reader

    with Reader(bag) as reader:
        assert sum(1 for _ in reader.messages()) == kept


def test_ctrl_c_writes_metadata_and_a_full_disk_stops_cleanly(tmp_path):
    env = graph_env(35, tmp_path)
    nodes = _big_talker(env)
    try:
        recorder = roc_process("bag", "record", "/big", "-o", "interrupted", env=env, cwd=tmp_path)
        wait_subscribed(recorder, ["/big"])
        _wait_for_size(tmp_path / "interrupted" / "interrupted_0.mcap", 768 * 1024)
        summary = interrupt(recorder)
        metadata = yaml.safe_load((tmp_path / "interrupted" / "metadata.yaml").read_text())
        assert metadata["rosbag2_bagfile_information"]["message_count"] > 0
        assert "Lost messages: 0" in summary

        def small_disk() -> None:  # files may not grow past 2 MB: writes past it fail as on a full disk
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (2 * 2**20, 2 * 2**20))

        full = roc_process("bag", "record", "/big", "-o", "full", env=env, cwd=tmp_path, preexec_fn=small_disk)
        assert full.wait(timeout=120) == 1
        errors = full.stderr.read()
        assert "the disk is full" in errors and "Traceback" not in errors
    finally:
        for node in nodes:
            stop_process(node)
    with Bag(tmp_path / "full") as bag:
        assert bag.metadata.message_count > 0 and sum(1 for _ in bag.messages()) == bag.metadata.message_count


def test_play_options_select_rename_cut_and_clock(tmp_path):
    """--topics, --remap, --start-offset, --playback-duration and --clock on a bag of two 100 Hz topics. The
    remapping is the player node's, as rosbag2 passes it (--ros-args --remap): rcl does not warn that a
    rule on the command line is deprecated syntax."""
    from rclpy.serialization import serialize_message
    from std_msgs.msg import String

    from roc.bag.definitions import definition
    from roc.bag.metadata import Topic
    from roc.bag.qos import default_profile
    from roc.bag.writer import BagWriter, WriteOptions

    writer = BagWriter(tmp_path / "source", WriteOptions())
    for name in ("/a", "/b"):
        writer.add_topic(Topic(name, "std_msgs/msg/String", "cdr", [default_profile()]),
                         definition("std_msgs/msg/String"))
    start_ns = 1_700_000_000_000_000_000
    for index in range(100):
        for name in ("/a", "/b"):
            writer.write(name, serialize_message(String(data=f"{name} {index}")), start_ns + index * 10_000_000)
    writer.close()
    env = graph_env(33, tmp_path)
    recorder = roc_process("bag", "record", "/renamed", "/clock", "-o", "out", env=env, cwd=tmp_path)
    try:
        output = play_when_recorder_listens(tmp_path / "source", recorder, ["/renamed", "/clock"], env, tmp_path,
                                            "--topics", "/a", "--remap", "a:=renamed", "--start-offset", "0.2",
                                            "--playback-duration", "0.5", "--clock", "100")
        assert "Played 51 messages on 1 topic" in output
        assert "deprecated" not in output and "[rcl]" not in output, output
        interrupt(recorder)
    finally:
        stop_process(recorder)
    found = messages(tmp_path / "out")
    from rclpy.serialization import deserialize_message

    assert [deserialize_message(d, String).data for d in found["/renamed"]] == [f"/a {i}" for i in range(20, 71)]
    assert found["/clock"]


def test_arrow_keys_step_and_change_the_rate_and_a_sim_time_recording_takes_the_clock(tmp_path):
    """On a terminal, paused: the right arrow plays one message each, up and down change the rate by 10 %,
    space resumes. A recorder with --use-sim-time writes each message at the time of the player's /clock
    (the bag's own times, years before now), not at its wall clock."""
    from rclpy.serialization import serialize_message
    from std_msgs.msg import String

    from roc.bag.definitions import definition
    from roc.bag.metadata import Topic
    from roc.bag.qos import default_profile
    from roc.bag.writer import BagWriter, WriteOptions

    writer = BagWriter(tmp_path / "source", WriteOptions())
    writer.add_topic(Topic("/a", "std_msgs/msg/String", "cdr", [default_profile()]), definition("std_msgs/msg/String"))
    start_ns = 1_600_000_000_000_000_000  # September 2020
    for index in range(40):
        writer.write("/a", serialize_message(String(data=f"{index}")), start_ns + index * 20_000_000)
    writer.close()
    env = graph_env(34, tmp_path)
    listener = start_nodes([{"name": "listener", "subscribers": [{"topic": "a", "type": "std_msgs/msg/String",
                                                                 "print": True}]}], env)[0]
    wall = roc_process("bag", "record", "/a", "-o", "wall", env=env, cwd=tmp_path)
    simulated = roc_process("bag", "record", "/a", "--use-sim-time", "-o", "sim", env=env, cwd=tmp_path)
    controller, terminal = pty.openpty()
    player = None
    try:
        # three subscribers of /a: the listener and both recorders, each matched before anything plays
        player = start([str(BIN / "roc"), "bag", "play", "-p", "--clock", "200", "--wait-for-all-acked", "10000",
                        "--wait-for-subscribers", "3", str(tmp_path / "source")], env, tmp_path, stdin=terminal)
        wait_for_line(player, "Paused")
        wait_subscribed(wall, ["/a"])  # the recorders find /a once the player advertises it
        wait_subscribed(simulated, ["/a"])
        first = None
        while first is None:  # right arrow: one message; pressed until the listener has matched the player
            os.write(controller, b"\x1b[C")
            first = _heard_index(listener, 2.0)
        for _ in range(2):
            os.write(controller, b"\x1b[C")
        assert [_heard_index(listener, 10.0), _heard_index(listener, 10.0)] == [first + 1, first + 2]
        assert _heard_index(listener, 1.0) is None  # paused: nothing more
        os.write(controller, b"\x1b[A")  # up: 10 % faster
        assert "Rate: 1.100" in wait_for_line(player, "Rate:")[-1]
        os.write(controller, b"\x1b[B\x1b[B")  # down twice
        wait_for_line(player, "Rate:")
        assert "Rate: 0.909" in wait_for_line(player, "Rate:")[-1]
        os.write(controller, b" ")
        output = "".join(wait_for_line(player, "Played", timeout=60))
        assert "Played 40 messages on 1 topic" in output, output
        assert player.wait(timeout=60) == 0, player.stderr.read()
        interrupt(wall)
        interrupt(simulated)
    finally:
        os.close(controller)
        os.close(terminal)
        for process in (player, wall, simulated, listener):
            if process is not None:
                stop_process(process)
    with Bag(tmp_path / "wall") as bag:
        wall_times = [m.log_time for m in bag.messages()]
    assert len(wall_times) == 40 and min(wall_times) > start_ns + 10**17  # now, not 2020
    with Bag(tmp_path / "sim") as bag:
        sim_times = [m.log_time for m in bag.messages()]
    # stamped with /clock: within the bag's own span (messages before the first /clock are left out)
    assert sim_times and all(start_ns <= t <= start_ns + 40 * 20_000_000 + 10**9 for t in sim_times), sim_times[:3]


def _heard_index(listener: subprocess.Popen, timeout: float) -> int | None:
    """The index (the String's data) of the next message the listener node printed, None if none came."""
    line = read_line(listener, timeout)
    if not line:
        return None
    return int(re.search(r"data='(\d+)'", line).group(1))


def test_wait_for_subscribers_holds_playback_until_each_topic_is_heard(tmp_path):
    """--wait-for-subscribers: a bag of volatile messages played before anyone listens would be lost;
    the player waits, and a listener that comes a few seconds later hears every message."""
    from rclpy.serialization import serialize_message
    from std_msgs.msg import String

    from roc.bag.definitions import definition
    from roc.bag.metadata import Topic
    from roc.bag.qos import default_profile
    from roc.bag.writer import BagWriter, WriteOptions

    writer = BagWriter(tmp_path / "source", WriteOptions())
    writer.add_topic(Topic("/a", "std_msgs/msg/String", "cdr", [default_profile()]), definition("std_msgs/msg/String"))
    for index in range(20):
        writer.write("/a", serialize_message(String(data=f"{index}")), 1_700_000_000_000_000_000 + index * 5_000_000)
    writer.close()
    env = graph_env(35, tmp_path)
    player = roc_process("bag", "play", "--wait-for-subscribers", "--wait-for-all-acked", "10000",
                         "--disable-keyboard-controls", str(tmp_path / "source"), env=env, cwd=tmp_path)
    listener = None
    try:
        wait_for_line(player, "Waiting for a subscriber on each of 1 topic")
        assert read_line(player, 2.0) is None  # nothing played, nobody listens
        listener = start_nodes([{"name": "listener", "subscribers": [
            {"topic": "a", "type": "std_msgs/msg/String", "depth": 100, "print": True}]}], env)[0]
        assert "Played 20 messages on 1 topic" in "".join(wait_for_line(player, "Played", timeout=60))
        assert player.wait(timeout=30) == 0, player.stderr.read()
        assert [_heard_index(listener, 10.0) for _ in range(20)] == list(range(20))
    finally:
        for process in (player, listener):
            if process is not None:
                stop_process(process)


def test_a_type_only_the_bag_defines_is_built_once_and_played(tmp_path):
    """A bag of a type no installed package has: the player builds it from the bag's own definitions
    into roc's cache (once), starts again with it sourced and plays; a recorder that has the built
    type gets the same bytes. A second play builds nothing."""
    from roc.bag.built_types import environment_with
    from roc.ros.types import UnknownTypeError, message_class

    with pytest.raises(UnknownTypeError):
        message_class(BAG_ONLY_TYPE)
    sent = write_bag_only_bag(tmp_path / "source", 10)
    env = graph_env(35, tmp_path, ROC_CACHE_DIR=str(tmp_path / "cache"))
    player = roc_process("bag", "play", "--wait-for-subscribers", "--wait-for-all-acked", "10000",
                         "--disable-keyboard-controls", "source", env=env, cwd=tmp_path)
    recorder = None
    try:
        wait_for_line(player, "Waiting for a subscriber", timeout=180)  # after the build
        (prefix,) = (tmp_path / "cache" / "bag-types").iterdir()
        recorder = roc_process("bag", "record", "/vec", "-o", "out", env=environment_with(prefix, env), cwd=tmp_path)
        wait_subscribed(recorder, ["/vec"])
        assert "Played 10 messages on 1 topic" in "".join(wait_for_line(player, "Played", timeout=60))
        assert player.wait(timeout=30) == 0
        assert f"building bagonly_msgs from the bag's own definitions (not installed here; once, into {prefix})" in (
            player.stderr.read())
        interrupt(recorder)
    finally:
        for process in (player, recorder):
            if process is not None:
                stop_process(process)
    assert messages(tmp_path / "out") == {"/vec": sent}
    with Bag(tmp_path / "out") as bag:
        assert "bagonly_msgs/Vec3 vec" in bag.definitions()[BAG_ONLY_TYPE].text
    again = subprocess.run([str(BIN / "roc"), "bag", "play", "--disable-keyboard-controls", "source"], env=env,
                           cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert again.returncode == 0 and "Played 10 messages" in again.stdout
    assert "building" not in again.stderr
