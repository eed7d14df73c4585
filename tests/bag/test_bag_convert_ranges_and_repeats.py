"""roc bag convert's per-topic ranges (ros2/rosbag2#2020) and the repeating of transient local topics
at the start of every file (ros2/rosbag2#1159), checked by readers that are not roc's: rosbags for
the bags, the mcap library for each split file on its own."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest
import yaml
from helpers.build import BIN

from roc.bag.definitions import definition
from roc.bag.metadata import Topic
from roc.bag.qos import default_profile
from roc.bag.writer import BagWriter, WriteOptions

START = 1_700_000_000_000_000_000
LATCHED = {**default_profile(), "durability": "transient_local", "depth": 1}


def string_cdr(text: str) -> bytes:
    from rclpy.serialization import serialize_message
    from std_msgs.msg import String

    return serialize_message(String(data=text))


@pytest.fixture(scope="module")
def source(tmp_path_factory) -> Path:
    """3 s of /data at 100 Hz ("data N"), /other at 10 Hz, and one /tf_static (transient local) at the start."""
    path = tmp_path_factory.mktemp("source") / "in"
    writer = BagWriter(path, WriteOptions())
    for name, qos in (("/tf_static", LATCHED), ("/data", default_profile()), ("/other", default_profile())):
        writer.add_topic(Topic(name, "std_msgs/msg/String", "cdr", [qos]), definition("std_msgs/msg/String"))
    writer.write("/tf_static", string_cdr("static"), START)
    for index in range(300):
        time = START + 1_000_000 + index * 10_000_000
        writer.write("/data", string_cdr(f"data {index}"), time)
        if index % 10 == 0:
            writer.write("/other", string_cdr(f"other {index // 10}"), time + 1)
    writer.close()
    return path


def convert(source: Path, tmp_path: Path, *outputs: dict) -> subprocess.CompletedProcess:
    options = tmp_path / "out.yaml"
    options.write_text(yaml.safe_dump({"output_bags": [{"storage_id": "mcap", **o} for o in outputs]}))
    return subprocess.run([str(BIN / "roc"), "bag", "convert", "-i", str(source), "-o", str(options)],
                          capture_output=True, text=True, timeout=120, cwd=tmp_path, env=dict(os.environ))


def by_rosbags(bag: Path) -> list[tuple[str, int, str]]:
    """(topic, log time, String data) of every message, as rosbags reads the bag."""
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    with Reader(bag) as reader:
        return [(c.topic, t, store.deserialize_cdr(d, c.msgtype).data) for c, t, d in reader.messages()]


def each_file(bag: Path) -> list[list[tuple[str, int, str]]]:
    """Each split file's messages, read from that file alone by the mcap library."""
    from mcap.reader import make_reader
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    files = []
    for path in sorted(bag.glob("*.mcap"), key=lambda p: int(p.stem.rsplit("_", 1)[1])):
        with open(path, "rb") as handle:
            files.append([(channel.topic, message.log_time, store.deserialize_cdr(message.data, schema.name).data)
                          for schema, channel, message in make_reader(handle).iter_messages(log_time_order=False)])
    return files


@pytest.mark.slow
def test_each_split_file_begins_with_the_latest_transient_local_message(source, tmp_path):
    result = convert(source, tmp_path, {"uri": "split", "all_topics": True, "max_bagfile_duration": 1,
                                        "repeat_transient_local_messages": {"/tf_static": 1}},
                     {"uri": "plain", "all_topics": True, "max_bagfile_duration": 1})
    assert result.returncode == 0, result.stderr
    files = each_file(tmp_path / "split")
    assert len(files) >= 3
    for index, messages in enumerate(files):
        assert messages[0][0::2] == ("/tf_static", "static")
        if index:  # repeated: stamped with the time of the message that opens the file
            assert messages[0][1] == messages[1][1]
        assert [m for m in messages[1:] if m[0] == "/tf_static"] == []
    # without the option only the first file has it, and otherwise the files hold the same messages
    plain = each_file(tmp_path / "plain")
    assert [sum(m[0] == "/tf_static" for m in f) for f in plain] == [1] + [0] * (len(plain) - 1)
    assert [[m for m in f if m[0] != "/tf_static"] for f in plain] == [
        [m for m in f if m[0] != "/tf_static"] for f in files]
    # the bag as a whole, read by rosbags: one /tf_static per file, in time order
    whole = by_rosbags(tmp_path / "split")
    assert sum(m[0] == "/tf_static" for m in whole) == len(files)
    assert [m[1] for m in whole] == sorted(m[1] for m in whole)


def test_a_cut_after_the_latched_message_begins_with_it_when_asked(source, tmp_path):
    start = START + 1_000_000_000
    result = convert(source, tmp_path, {"uri": "cut", "all_topics": True, "start_time_ns": start,
                                        "repeat_all_transient_local_depth": 1},
                     {"uri": "bare", "all_topics": True, "start_time_ns": start})
    assert result.returncode == 0, result.stderr
    cut, bare = by_rosbags(tmp_path / "cut"), by_rosbags(tmp_path / "bare")
    assert cut[0] == ("/tf_static", bare[0][1], "static") and cut[1:] == bare
    assert all(m[0] != "/tf_static" for m in bare) and bare[0][1] >= start


def test_per_topic_message_and_time_ranges(source, tmp_path):
    first, last = START + 1_000_000 + 50 * 10_000_000, START + 1_000_000 + 149 * 10_000_000 + 1
    result = convert(source, tmp_path, {"uri": "ranges", "all_topics": True,
                                        "topic_message_ranges": {"/data": [100, 199]},
                                        "topic_time_ranges": {"/other": [first, last]}})
    assert result.returncode == 0, result.stderr
    messages = by_rosbags(tmp_path / "ranges")
    assert [m[2] for m in messages if m[0] == "/data"] == [f"data {i}" for i in range(100, 200)]
    assert [m[2] for m in messages if m[0] == "/other"] == [f"other {i}" for i in range(5, 15)]
    assert [m[2] for m in messages if m[0] == "/tf_static"] == ["static"]


@pytest.mark.parametrize(("ranges", "error"), [
    ({"topic_message_ranges": {"/data": [100, 300]}}, "topic_message_ranges: /data: message 300 is past the last "
                                                      "one (the inputs hold 300, numbered from 0)"),
    ({"topic_message_ranges": {"/data": [5, 4]}}, "topic_message_ranges: /data: the first (5) is after the last (4)"),
    ({"topic_time_ranges": {"/nothing": [0, 1]}}, "topic_time_ranges: /nothing: no input bag has this topic"),
    ({"topic_message_ranges": {"/data": "all"}}, "topic_message_ranges: /data: expected [first, last]"),
    ({"repeat_transient_local_messages": {"/tf_static": 0}},
     "repeat_transient_local_messages: /tf_static: expected a positive integer, got 0"),
])
def test_a_bad_range_names_the_file_output_and_topic(source, tmp_path, ranges, error):
    from roc.bag.convert import convert as convert_bags
    from roc.bag.convert import read_output_options
    from roc.errors import UsageError

    options = tmp_path / "out.yaml"
    options.write_text(yaml.safe_dump({"output_bags": [{"uri": str(tmp_path / "bad"), "all_topics": True, **ranges}]}))
    with pytest.raises(UsageError) as raised:
        convert_bags([(str(source), None)], read_output_options(options))
    assert str(raised.value) == f"{options}: output_bags[0]: {error}"
    assert not (tmp_path / "bad").exists()


def test_a_bad_range_is_one_line_and_writes_nothing(source, tmp_path):
    result = convert(source, tmp_path, {"uri": "bad", "all_topics": True, "topic_message_ranges": {"/data": [5, 4]}})
    assert (result.returncode, result.stdout) == (2, "")
    assert result.stderr == (f"roc: error: {tmp_path / 'out.yaml'}: output_bags[0]: topic_message_ranges: /data: "
                             "the first (5) is after the last (4) (see 'roc bag convert --help')\n")
    assert not (tmp_path / "bad").exists()


def test_record_refuses_a_bad_repeat_before_joining_the_graph(tmp_path):
    result = subprocess.run([str(BIN / "roc"), "bag", "record", "/tf", "-o", str(tmp_path / "bag"),
                             "--repeat-transient-local", "/tf_static=0"], capture_output=True, text=True, timeout=60)
    assert (result.returncode, result.stderr) == (2, "roc: error: --repeat-transient-local: '/tf_static=0' is not "
                                                     "TOPIC or TOPIC=DEPTH (a positive number) (see 'roc bag record "
                                                     "--help')\n")
    assert not (tmp_path / "bag").exists()


def test_record_options_name_topics_and_depths():
    from roc.commands.bag.record import repeat_options
    from roc.errors import UsageError

    assert repeat_options(None, 0) == ({}, 0)
    assert repeat_options([], 0) == ({}, 1)  # the option alone: every transient local topic
    assert repeat_options(["tf_static", "/map=3"], 2) == ({"/tf_static": 1, "/map": 3}, 2)
    for bad in ("/map=x", "=2", "/map=-1"):
        with pytest.raises(UsageError, match=f"'{bad}' is not TOPIC or TOPIC=DEPTH"):
            repeat_options([bad], 0)
