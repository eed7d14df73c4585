"""roc pkg beside the oracle, ros2 pkg, over every prefix of the ament index (the wheels' venv, the oracle's
venv, a sourced overlay built by roc); roc run: ros2 run's lookup, arguments passed untouched, exit code and
signals passed back (roc becomes the node), one-line errors listing what exists."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.build import BIN
from helpers.graph import install_oracle, roc, ros2, stop_daemon
from helpers.launch import demo_env, kill_leftovers, wait_for_nodes

PACKAGE = "roc_launch_demo"
pytestmark = pytest.mark.xdist_group("pkg_run")  # one worker: the demo package built once for its tests


@pytest.fixture(scope="module")
def demo(tmp_path_factory, launch_demo_prefix):
    prefix = launch_demo_prefix
    env = demo_env(28, tmp_path_factory.mktemp("runtime"), prefix)
    yield env, prefix
    stop_daemon(env)
    kill_leftovers(str(prefix))


@pytest.fixture(scope="module")
def oracle():
    reason = install_oracle()
    if reason:
        pytest.skip(f"no ros2 oracle: {reason}")


@pytest.mark.slow
@pytest.mark.parametrize("verb", [
    ["list"], ["executables"], ["executables", PACKAGE], ["executables", "--full-path", PACKAGE],
    ["prefix", PACKAGE], ["prefix", "--share", "rclpy"], ["xml", PACKAGE], ["xml", "std_msgs", "-t", "depend"],
    ["xml", "rclpy", "--tag", "version"],
], ids=lambda verb: "-".join(verb))
def test_pkg_prints_what_ros2_pkg_prints(demo, oracle, verb: list[str]) -> None:
    env, _ = demo
    ours, theirs = roc("pkg", *verb, env=env), ros2("pkg", *verb, env=env)
    assert (ours.returncode, ours.stdout) == (theirs.returncode, theirs.stdout), ours.stderr
    assert ours.stdout


def test_pkg_json_and_the_prefixes_it_covers(demo, tmp_path: Path) -> None:
    env, prefix = demo
    # a prefix between the overlay and the wheels' venv, made here (not the oracle's venv, which may be
    # missing or half-installed on a fresh machine)
    other = tmp_path / "other"
    (other / "share" / "ament_index" / "resource_index" / "packages").mkdir(parents=True)
    (other / "share" / "ament_index" / "resource_index" / "packages" / "other_pkg").touch()
    env = {**env, "AMENT_PREFIX_PATH": os.pathsep.join([str(prefix), str(other), sys.prefix])}
    listed = json.loads(roc("pkg", "list", "--format", "json", env=env).stdout)
    where = {entry["name"]: entry["prefix"] for entry in listed}
    assert (where[PACKAGE], where["other_pkg"], where["rclpy"]) == (str(prefix), str(other), sys.prefix)
    executables = json.loads(roc("pkg", "executables", PACKAGE, "--format", "json", env=env).stdout)
    assert [e["executable"] for e in executables] == ["args", "crasher", "listener", "server", "talker"]
    assert executables[0]["path"] == str(prefix / "lib" / PACKAGE / "args")
    tag = json.loads(roc("pkg", "xml", PACKAGE, "-t", "exec_depend", "--format", "json", env=env).stdout)
    assert tag == {"package": PACKAGE, "tag": "exec_depend", "values": ["rclpy", "std_msgs", "std_srvs"]}


def test_pkg_errors_are_one_line(demo) -> None:
    env, _ = demo
    unknown = roc("pkg", "prefix", "roc_launch_dem", env=env)
    assert unknown.returncode == 1 and unknown.stderr.count("\n") == 1
    assert "package 'roc_launch_dem' not found in the ament index (" in unknown.stderr
    assert "did you mean roc_launch_demo?" in unknown.stderr
    no_tag = roc("pkg", "xml", PACKAGE, "-t", "nope", env=env)
    assert no_tag.returncode == 1 and "package.xml: no <nope> element (tags: buildtool_depend" not in no_tag.stderr
    assert "no <nope> element (tags: description, exec_depend, export, license, maintainer, name, version)" \
        in no_tag.stderr


@pytest.mark.slow  # over a second (the quick loop stays under 45 s)
def test_run_passes_arguments_untouched_and_the_exit_code_back(demo) -> None:
    env, _ = demo
    words = ["a", "b c", "--ros-args", "-p", "x:=1", "--debug", "-r", "__node:=n"]
    ran = roc("run", PACKAGE, "args", *words, env={**env, "ROC_DEMO_EXIT": "7"})
    assert ran.returncode == 7
    assert json.loads(ran.stdout) == words
    prefixed = roc("run", "--prefix", "env ROC_DEMO_EXIT=4", PACKAGE, "args", "x", env=env)
    assert (prefixed.returncode, json.loads(prefixed.stdout)) == (4, ["x"])


@pytest.mark.slow
def test_run_becomes_the_node_so_signals_reach_it_once(demo, tmp_path: Path) -> None:
    env, _ = demo
    for signum, code in ((signal.SIGINT, 0), (signal.SIGKILL, -signal.SIGKILL)):
        node = subprocess.Popen([str(BIN / "roc"), "run", PACKAGE, "talker", "--ros-args", "-r", "__node:=runner"],
                                env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        try:
            wait_for_nodes(env, {"/runner"})
            command = Path(f"/proc/{node.pid}/cmdline").read_bytes().split(b"\0")
            assert command[1].endswith(b"/lib/roc_launch_demo/talker")  # the pid roc had is the node's now
            node.send_signal(signum)
            assert node.wait(timeout=20) == code
        finally:
            if node.poll() is None:
                node.kill()
                node.wait()
        assert "Traceback" not in node.stderr.read()  # one SIGINT, handled by the node: no interrupted clean-up


def test_run_errors_list_what_exists(demo) -> None:
    env, _ = demo
    missing = roc("run", PACKAGE, "talk", env=env)
    assert missing.returncode == 1
    assert missing.stderr == ("roc: error: package 'roc_launch_demo' has no executable 'talk'; did you mean "
                              "'talker'? (its executables: args, crasher, listener, server, talker)\n")
    assert "did you mean roc_launch_demo?" in roc("run", "roc_lanch_demo", "talker", env=env).stderr
