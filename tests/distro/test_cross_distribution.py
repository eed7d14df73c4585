"""What one ROS 2 distribution made, used on the other (run in the Kilted suite, where both venvs exist):
a bag recorded with roc on Jazzy is read and played by roc on Kilted, and the other way round, byte for
byte; a workspace built on one distribution is refused by roc work build (and --explain) on the other, and so
is an overlay that sources it over the other (roc doctor says the same); in a shell that sources both, every
verb that would load rclpy refuses in one line instead of crashing."""

from __future__ import annotations

import json
import signal
import subprocess
from pathlib import Path

import pytest
from helpers.build import DISTRO, NODES, add_cmake_package, stop_process
from helpers.distro import DISTROS, OTHER, env_of, require_both, venv
from helpers.graph import read_line

from roc.bag.reader import Bag

pytestmark = [pytest.mark.distro, pytest.mark.slow]
BAG_NODE = NODES / "bag_node.py"
TYPES = ["test_msgs/msg/BasicTypes", "test_msgs/msg/Strings", "test_msgs/msg/Arrays"]
TOPICS = ["/basictypes", "/strings", "/arrays"]
COUNT = 5


def _run(distro: str, *args: str, env: dict[str, str], cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([str(venv(distro) / "bin" / "roc"), *args], env=env, cwd=cwd, capture_output=True,
                          text=True, timeout=timeout)


def _recorder(distro: str, output: str, env: dict[str, str], cwd: Path) -> subprocess.Popen:
    """roc bag record of TOPICS on ``distro``."""
    return subprocess.Popen([str(venv(distro) / "bin" / "roc"), "bag", "record", *TOPICS, "-o", output],
                            env=env, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _wait_subscribed(recorder: subprocess.Popen) -> None:
    pending = {f"Subscribed to topic '{topic}'" for topic in TOPICS}
    while pending:
        line = read_line(recorder, 60)
        if not line:
            stop_process(recorder)
            raise AssertionError(f"the recorder never subscribed to {pending}: {recorder.stderr.read()}")
        pending.discard(line.strip())


def _stop(recorder: subprocess.Popen) -> str:
    """Ctrl+C the recorder; the rest of its output (its summary)."""
    recorder.send_signal(signal.SIGINT)
    rest = []
    while (line := read_line(recorder, 60)) not in ("", None):
        rest.append(line)
    assert recorder.wait(timeout=60) == 0, recorder.stderr.read()
    return "".join(rest)


def _messages(bag: Path) -> dict[str, list[bytes]]:
    found: dict[str, list[bytes]] = {}
    with Bag(bag) as opened:
        for message in opened.messages():
            found.setdefault(message.topic, []).append(message.data)
    return found


@pytest.mark.parametrize("writer", DISTROS)
def test_a_bag_written_on_one_distribution_reads_and_plays_on_the_other(tmp_path: Path, writer: str) -> None:
    require_both()
    reader = next(name for name in DISTROS if name != writer)
    written_env = env_of(writer, 48, tmp_path / "writer")
    read_env = env_of(reader, 48, tmp_path / "reader")

    recorder = _recorder(writer, "bag", written_env, tmp_path)
    publisher = subprocess.Popen([str(venv(writer) / "bin" / "python"), str(BAG_NODE), "publish", str(COUNT), "20",
                                  *TYPES], env=written_env, cwd=tmp_path, stdout=subprocess.PIPE, text=True)
    try:
        _wait_subscribed(recorder)
        assert read_line(publisher, 60) == "ready\n"
        assert read_line(publisher, 60) == "done\n"
        assert "Lost messages: 0" in _stop(recorder)
    finally:
        stop_process(publisher)
        stop_process(recorder)
    written = _messages(tmp_path / "bag")
    assert {topic: len(data) for topic, data in written.items()} == dict.fromkeys(TOPICS, COUNT)

    info = _run(reader, "bag", "info", "bag", env=read_env, cwd=tmp_path)
    assert info.returncode == 0, info.stderr
    assert f"ROS Distro:        {writer}" in info.stdout and f"Messages:          {COUNT * len(TOPICS)}" in info.stdout

    replay = _recorder(reader, "replay", read_env, tmp_path)
    try:
        played = _run(reader, "bag", "play", "bag", "--wait-for-subscribers", "--wait-for-all-acked", "10000",
                      env=read_env, cwd=tmp_path, timeout=120)
        assert played.returncode == 0, played.stderr
        _wait_subscribed(replay)
        _stop(replay)
    finally:
        stop_process(replay)
    assert _messages(tmp_path / "replay") == written  # byte for byte, in order, every type
    with Bag(tmp_path / "replay") as bag:
        assert bag.metadata.ros_distro == reader


CMAKELISTS = "cmake_minimum_required(VERSION 3.16)\nproject({name} NONE)\ninstall(FILES CMakeLists.txt DESTINATION share/{name})\n"


def test_a_workspace_built_on_one_distribution_is_refused_on_the_other(tmp_path: Path) -> None:
    require_both()
    workspace, overlay = tmp_path / "ws", tmp_path / "overlay"
    add_cmake_package(workspace, "base", CMAKELISTS.format(name="base"))
    add_cmake_package(overlay, "top", CMAKELISTS.format(name="top"), depends=("base",))
    other_env = env_of(OTHER, 49, tmp_path / "other")
    own_env = env_of(DISTRO, 49, tmp_path / "own")
    built = _run(OTHER, "work", "build", env=other_env, cwd=workspace)
    assert built.returncode == 0, built.stderr
    stamp = (workspace / "install" / "base" / "share" / "base" / "CMakeLists.txt").stat().st_mtime_ns

    for explain in ((), ("--explain",)):  # --explain answers what the build would
        again = _run(DISTRO, "work", "build", *explain, env=own_env, cwd=workspace)
        assert again.returncode == 1 and again.stdout == "", again.stdout
        assert len(again.stderr.splitlines()) == 1, again.stderr
        assert f"was built with ROS 2 {OTHER}, but the sourced ROS 2 is {DISTRO}" in again.stderr
    assert (workspace / "install" / "base" / "share" / "base" / "CMakeLists.txt").stat().st_mtime_ns == stamp

    # the workspace sourced as an underlay over this distribution: its setup script chains the other's ROS 2
    sourced = f"source {workspace}/install/setup.bash && "
    on_top = subprocess.run(["bash", "-c", sourced + "roc work build"], env=own_env, cwd=overlay, capture_output=True,
                            text=True, timeout=120)
    assert on_top.returncode == 1 and len(on_top.stderr.splitlines()) == 1, on_top.stderr
    assert "two ROS 2 distributions are sourced" in on_top.stderr
    assert all(f"{name} (rclpy " in on_top.stderr for name in DISTROS), on_top.stderr
    explained = subprocess.run(["bash", "-c", sourced + "roc work build --explain"], env=own_env, cwd=overlay,
                               capture_output=True, text=True, timeout=120)
    assert explained.returncode == 1 and "two ROS 2 distributions are sourced" in explained.stderr, explained.stderr
    assert not (overlay / "install").exists() and not (overlay / "build").exists()
    doctor = subprocess.run(["bash", "-c", sourced + "roc doctor --no-daemon --spin-time 0.5 --format json"], env=own_env, cwd=overlay,
                            capture_output=True, text=True, timeout=120)
    found = {f["check"]: f for f in json.loads(doctor.stdout)["findings"]}
    assert found["distribution"]["level"] == "error", doctor.stdout
    assert all(f"{name} (rclpy " in found["distribution"]["message"] for name in DISTROS), doctor.stdout
    assert doctor.returncode == 1, doctor.stderr
    assert found["graph"]["level"] == "error" and "not checked" in found["graph"]["message"], doctor.stdout


# Each verb that loads rclpy (in roc's process, a daemon's or a launch's), with what stops it early.
RCLPY_VERBS = (("topic", "list"), ("node", "list", "--no-daemon"), ("daemon", "start"), ("bag", "record", "-a"),
               ("frame", "pub", "map", "odom"), ("bridge", "/a", "--from-domain", "1", "--to-domain", "2"),
               ("service", "call", "/s", "std_srvs/srv/Trigger"), ("launch", "demo_py", "nothing.launch.py"))


def test_every_verb_that_loads_rclpy_refuses_two_distributions_in_one_line(tmp_path: Path) -> None:
    """The other distribution's workspace sourced over this one's roc: its rclpy comes first on the paths,
    and loading it on this distribution's libraries used to end in std::bad_array_new_length and a
    segmentation fault (exit 139)."""
    require_both()
    workspace = tmp_path / "ws"
    add_cmake_package(workspace, "base", CMAKELISTS.format(name="base"))
    other_env = env_of(OTHER, 49, tmp_path / "other")
    assert _run(OTHER, "work", "build", env=other_env, cwd=workspace).returncode == 0
    own_env = env_of(DISTRO, 49, tmp_path / "own")
    for verb in RCLPY_VERBS:
        done = subprocess.run(["bash", "-c", f"source {workspace}/install/setup.bash && roc \"$@\"", "roc", *verb],
                              env=own_env, cwd=tmp_path, capture_output=True, text=True, timeout=120)
        assert done.returncode == 1 and done.stdout == "", (verb, done.stdout, done.stderr)
        assert done.stderr.startswith("roc: error: two ROS 2 distributions are sourced: "), (verb, done.stderr)
        assert len(done.stderr.splitlines()) == 1 and all(f"{name} (rclpy " in done.stderr for name in DISTROS), \
            (verb, done.stderr)
    assert not list((tmp_path / "own").glob("roc/daemon-*.sock")), "no daemon started"
