"""roc frame verbs on a live tf tree: tf2_msgs built by roc from the example workspace, sourced, and a
tree published by real rclpy nodes (tests/nodes/tf_node.py): map->odom (static), odom->base_link (20 Hz,
yaw 90 degrees), base_link->laser (static), and a second tree camera->lens."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers.build import BIN, NODES, stop_process
from helpers.graph import graph_env, install_oracle, read_line, ros2, stop_daemon, wait_for, with_tf2_msgs

pytestmark = pytest.mark.slow
TF_NODE = NODES / "tf_node.py"


@pytest.fixture(scope="module")
def sourced(tmp_path_factory):
    """A graph environment with the built tf2_msgs sourced."""
    env = with_tf2_msgs(graph_env(6, tmp_path_factory.mktemp("runtime")))
    yield env
    stop_daemon(env)


@pytest.fixture(scope="module")
def tree(sourced):
    """Two tf publisher nodes: /tf_publish (map->odom->base_link->laser), /tf_camera (camera->lens on /tf)."""
    processes = [subprocess.Popen([sys.executable, str(TF_NODE), mode], env=sourced, stdout=subprocess.PIPE,
                                  stderr=subprocess.DEVNULL, text=True) for mode in ("publish", "camera")]
    try:
        assert [read_line(process, 60) for process in processes] == ["ready\n", "ready\n"]
        yield sourced
    finally:
        for process in processes:
            stop_process(process)


def frame(*args: str, env: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN / "roc"), "frame", *args], env=env, capture_output=True, text=True, timeout=60)


def test_echo_composes_the_chain(tree) -> None:
    result = frame("echo", "map", "laser", "--once", env=tree)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0].startswith("At time ")
    # map->odom (1, 0, 0), then odom->base_link turned 90 degrees, then base_link->laser (0, 1, 0): (0, 0, 0)
    assert lines[1:5] == ["- Translation: [0.000, 0.000, 0.000]",
                          "- Rotation: in Quaternion (xyzw) [0.000, 0.000, 0.707, 0.707]",
                          "- Rotation: in RPY (radian) [0.000, 0.000, 1.571]",
                          "- Rotation: in RPY (degree) [0.000, 0.000, 90.000]"]
    as_json = json.loads(frame("echo", "laser", "map", "--once", "--format", "json", "--no-daemon", env=tree).stdout)
    assert as_json["translation"] == pytest.approx([0, 0, 0], abs=1e-9)
    assert as_json["rpy_degrees"][2] == pytest.approx(-90)


def test_unconnected_frames_are_one_error(tree) -> None:
    result = frame("echo", "map", "lens", "--timeout", "8", env=tree)  # (time for a cold daemon to start)
    assert result.returncode == 1
    assert result.stderr == ("roc: error: no transform from map to lens within 8 s: map and lens are not connected "
                             "(trees: camera->lens; map->odom->base_link->laser)\n")


def test_list_and_tree(tree, tmp_path: Path) -> None:
    rows = {r["frame"]: r for r in json.loads(frame("list", "--format", "json", "--duration", "1.5", env=tree).stdout)}
    assert sorted(rows) == ["base_link", "camera", "laser", "lens", "map", "odom"]
    assert (rows["odom"]["parent"], rows["odom"]["static"]) == ("map", True)
    assert rows["base_link"]["static"] is False and rows["base_link"]["rate"] == pytest.approx(20, rel=0.15)
    assert rows["map"]["parent"] is None and rows["map"]["publishers"] == []
    # each frame names the node that sent it, although both nodes publish /tf
    assert {frame: row["publishers"] for frame, row in rows.items() if row["parent"]} == {
        "odom": ["/tf_publish"], "base_link": ["/tf_publish"], "laser": ["/tf_publish"], "lens": ["/tf_camera"]}
    text = frame("tree", "--duration", "1", env=tree).stdout.splitlines()
    assert text[1].endswith(", /tf_camera]") and text[3] == "└── odom [static, /tf_publish]"
    assert [line.split(" [")[0] for line in text] == ["camera", "└── lens", "map", "└── odom", "    └── base_link",
                                                      "        └── laser"]
    dot = tmp_path / "tf.dot"
    assert frame("tree", "--duration", "1", "--output", str(dot), env=tree).returncode == 0
    assert '"odom" -> "base_link" [label="' in dot.read_text() and dot.read_text().startswith("digraph tf {")
    png, svg = tmp_path / "tf.png", tmp_path / "tf.svg"  # drawn by graphviz-pure (the test extra) or dot
    drawn = frame("tree", "--duration", "1", "--output", str(png), env=tree)
    assert drawn.returncode == 0, drawn.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    drawn = frame("tree", "--duration", "1", "--output", str(svg), env=tree)
    assert drawn.returncode == 0, drawn.stderr
    assert "<svg" in svg.read_text() and ">base_link</text>" in svg.read_text()


def test_monitor_gives_rate_delay_and_node_per_frame(tree) -> None:
    result = frame("monitor", "--duration", "2.5", "--format", "json", env=tree)
    assert result.returncode == 0, result.stderr
    last = {}
    for line in result.stdout.splitlines():
        row = json.loads(line)
        last[row["frame"]] = row
    assert sorted(last) == ["base_link", "lens"]  # dynamic frames only
    assert (last["base_link"]["publishers"], last["lens"]["publishers"]) == (["/tf_publish"], ["/tf_camera"])
    assert last["lens"]["rate"] == pytest.approx(10, rel=0.25) and 0 <= last["base_link"]["delay_average"] < 1


def test_a_frame_sent_by_two_nodes_names_both(tree) -> None:
    """A conflict a ROS user wants to see: lens also published by roc frame pub (its node, /roc_frame_pub_<pid>)."""
    pub = subprocess.Popen([str(BIN / "roc"), "frame", "pub", "camera", "lens", "--z", "2", "--rate", "10",
                            "--duration", "20"], env=tree, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    both, deadline = sorted([f"/roc_frame_pub_{pub.pid}", "/tf_camera"]), time.monotonic() + 30
    try:
        assert (read_line(pub) or "").startswith("publishing camera -> lens on /tf at 10 Hz")
        while True:  # (until the daemon has discovered the fresh publisher)
            rows = json.loads(frame("list", "--format", "json", "--duration", "2", env=tree).stdout)
            lens = {row["frame"]: row["publishers"] for row in rows}["lens"]
            if lens == both or time.monotonic() > deadline:
                break
    finally:
        stop_process(pub)
    assert lens == both


def test_what_frame_pub_publishes_is_listed_under_a_node_named_for_it_as_ros2_lists_it(tmp_path: Path) -> None:
    """roc frame pub publishes from the daemon, on a node of its own, /roc_frame_pub_<pid> (issue 51: on the
    daemon's hidden node, roc's lists left /tf_static out, which ros2 lists). A domain of its own: no
    other /tf_static publisher."""
    env = with_tf2_msgs(graph_env(54, tmp_path))
    pub = subprocess.Popen([str(BIN / "roc"), "frame", "pub", "map", "odom"], env=env, stdout=subprocess.PIPE,
                           stderr=subprocess.DEVNULL, text=True)
    node = f"roc_frame_pub_{pub.pid}"
    try:
        assert (read_line(pub) or "").startswith("publishing map -> odom on /tf_static")
        listed = subprocess.run([str(BIN / "roc"), "topic", "list"], env=env, capture_output=True, text=True, timeout=60)
        assert "/tf_static" in listed.stdout.splitlines(), listed.stdout
        info = subprocess.run([str(BIN / "roc"), "topic", "info", "/tf_static", "-v"], env=env, capture_output=True,
                              text=True, timeout=60)
        assert info.returncode == 0, info.stderr
        assert "Publisher count: 1" in info.stdout and f"Node name: {node}\n" in info.stdout, info.stdout
        nodes = subprocess.run([str(BIN / "roc"), "node", "list"], env=env, capture_output=True, text=True, timeout=60)
        assert f"/{node}" in nodes.stdout.splitlines(), nodes.stdout
        assert f"└── odom [static, /{node}]" in frame("tree", "--duration", "1", env=env).stdout
        if install_oracle() is None:  # the real ros2 lists the same topics and names the same node
            wait_for(lambda: "/tf_static" in ros2("topic", "list", env=env).stdout.splitlines())
            ros2_s_own = {"/parameter_events", "/rosout"}  # its daemon's node's (roc lists none of its own)
            assert [t for t in ros2("topic", "list", env=env).stdout.splitlines() if t not in ros2_s_own] == \
                listed.stdout.splitlines()
            assert f"Node name: {node}\n" in ros2("topic", "info", "/tf_static", "-v", env=env).stdout
    finally:
        stop_process(pub)
        stop_daemon(env)


def test_pub_reaches_a_real_subscriber_and_ctrl_c_stops_it(sourced) -> None:
    listener = subprocess.Popen([sys.executable, str(TF_NODE), "listen"], env=sourced, stdout=subprocess.PIPE,
                                stderr=subprocess.DEVNULL, text=True)
    pub = subprocess.Popen([str(BIN / "roc"), "frame", "pub", "world", "robot", "--x", "2.5"], env=sourced,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert read_line(listener, 60) == "ready\n"
        assert (read_line(pub) or "").startswith("publishing world -> robot on /tf_static")
        heard, deadline = [], time.monotonic() + 15  # (the tree's transforms too, while it is published)
        while {"parent": "world", "child": "robot", "x": 2.5} not in heard and time.monotonic() < deadline:
            line = read_line(listener, 0.5)
            if line:
                heard.append(json.loads(line))
        assert {"parent": "world", "child": "robot", "x": 2.5} in heard
        pub.send_signal(signal.SIGINT)
        assert pub.wait(timeout=10) == 130
    finally:
        stop_process(pub)
        stop_process(listener)


def test_without_tf2_msgs_every_frame_verb_says_what_to_do(tmp_path: Path) -> None:
    env = graph_env(6, tmp_path)
    env = {k: v for k, v in env.items() if k != "PYTHONPATH"} | {"AMENT_PREFIX_PATH": os.environ.get("VIRTUAL_ENV", sys.prefix)}
    for verb in (["list"], ["echo", "a", "b"], ["tree"], ["monitor"], ["pub", "a", "b"]):
        result = frame(*verb, env=env)
        assert result.returncode == 1 and result.stderr.startswith("roc: error: tf2_msgs is not installed"), verb
