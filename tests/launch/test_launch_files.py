"""roc launch of launch files beside the oracle, ros2 launch: the same Python, XML and YAML files give the
same nodes, names, namespaces, parameters and remappings; launch arguments; --show-args and --print; the
errors for a file or package that does not exist."""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import pytest
from helpers.build import BIN
from helpers.graph import ORACLE_VENV, install_oracle, roc, ros2, stop_daemon
from helpers.launch import (
    demo_env,
    describe,
    kill_leftovers,
    nodes,
    process_view,
    processes_with,
    roc_launch,
    ros2_launch,
    skip_without_launch_library,
    wait_for_nodes,
    wait_until,
)

PACKAGE = "roc_launch_demo"
FORMATS = ["demo.launch.py", "demo.launch.xml", "demo.launch.yaml"]
NODES = {"/r7/talker", "/r7/listener", "/map_server"}


@pytest.fixture(scope="module")
def demo(tmp_path_factory, launch_demo_prefix):
    skip_without_launch_library()
    reason = install_oracle(launch=True)
    if reason:
        pytest.skip(f"no ros2 launch oracle: {reason}")
    prefix = launch_demo_prefix
    env = demo_env(29, tmp_path_factory.mktemp("runtime"), prefix)
    yield env, prefix
    stop_daemon(env)
    kill_leftovers(str(prefix))


def _node_processes(prefix: Path, launcher_pid: int) -> dict[str, dict]:
    """What ps shows of each node a launcher started, by name (the launch library's temporary parameter
    files' names left out), and whether it is in the process group of the process running the library
    (ros2 launch itself; roc's launch runner)."""
    views = {pid: process_view(pid) for pid in processes_with(str(prefix))}
    library = next((pid for pid, view in views.items() if "roc.launch.runner" in view["cmdline"]), launcher_pid)
    nodes = {}
    for pid, view in views.items():
        if pid != library and view["comm"] != "roc-forkserver":
            nodes[view["comm"]] = {"cmdline": [re.sub(r"launch_params_\w+", "launch_params_", word)
                                               for word in view["cmdline"]],
                                   "in the library's group": view["pgid"] == os.getpgid(library)}
    return nodes


def _started(output: str) -> list[str]:
    """The names of the processes a launcher said it started."""
    return sorted(re.findall(r"\[INFO\] \[([\w-]+)\]: process started with pid", output))


@pytest.mark.slow
@pytest.mark.parametrize("file", FORMATS)
def test_roc_and_ros2_launch_start_the_same_system(demo, tmp_path: Path, file: str) -> None:
    env, prefix = demo
    seen, outputs, processes = {}, {}, {}
    for tool, start in (("ros2", ros2_launch), ("roc", roc_launch)):
        launcher = start(PACKAGE, file, "robot:=r7", "rate:=2.5", env=env, log=tmp_path / f"{tool}.log")
        try:
            wait_for_nodes(env, NODES)
            wait_until(lambda: "/map_server/load_map" in roc("service", "list", env=env).stdout, 20,
                       "the map server's service")
            seen[tool] = describe(env, NODES)
            processes[tool] = _node_processes(prefix, launcher.pid)
        finally:
            assert launcher.stop() == 0, launcher.output()
        outputs[tool] = launcher.output()
        assert not kill_leftovers(str(prefix)), f"{tool} launch left processes behind"
        wait_until(lambda: not nodes(env) & NODES, 20, "the nodes to leave the graph")
    assert seen["roc"] == seen["ros2"]
    # roc forked the Python nodes from its warm interpreter, yet ps shows each as ros2 launch's: the same
    # name and command line, in the process group of the process that runs the launch library
    assert all("(warm start)" in (tmp_path / "log" / "latest_launch" / f"{name}.log").read_text()
               for name in ("talker-1", "listener-2", "server-3"))
    assert processes["roc"] == processes["ros2"]
    assert sorted(processes["roc"]) == ["listener", "server", "talker"]
    talker = seen["roc"]["/r7/talker"]
    assert talker["parameters"]["/r7/talker"]["ros__parameters"]["rate"] == 2.5  # a launch argument
    assert talker["parameters"]["/r7/talker"]["ros__parameters"]["greeting"] == "hello from launch"
    assert "/r7/news" in [topic["name"] for topic in talker["info"]["publishers"]]  # remapped from chatter
    assert seen["roc"]["/map_server"]["parameters"]["/map_server"]["ros__parameters"]["resolution"] == 0.05
    assert _started(outputs["roc"]) == _started(outputs["ros2"]) == ["listener-2", "server-3", "talker-1"]
    assert "[talker-1] [INFO] [" in outputs["roc"]  # the processes' output, prefixed as ros2 launch does


@pytest.mark.slow  # over a second (the quick loop stays under 45 s)
@pytest.mark.parametrize("file", [FORMATS[0], *(pytest.param(f, marks=pytest.mark.slow) for f in FORMATS[1:])])
def test_show_args_prints_what_ros2_launch_prints(demo, file: str) -> None:
    env, _ = demo
    ours = roc("launch", "-s", PACKAGE, file, env=env)
    theirs = ros2("launch", "--show-args", PACKAGE, file, env=env)
    assert (ours.returncode, ours.stdout) == (theirs.returncode, theirs.stdout), ours.stderr
    assert "'rate':\n        publishing rate of the talker\n        (default: '5.0')" in ours.stdout


@pytest.mark.slow
def test_print_describes_the_launch_file_as_ros2_launch_does(demo) -> None:
    env, prefix = demo
    path = prefix / "share" / PACKAGE / "launch" / "demo.launch.py"
    ours = roc("launch", "--print", str(path), env=env)
    theirs = ros2("launch", "-p", str(path), env=env)

    def without_addresses(text: str) -> str:
        return re.sub(r"0x[0-9a-f]+", "0x", text)

    assert ours.returncode == theirs.returncode == 0, ours.stderr
    assert without_addresses(ours.stdout) == without_addresses(theirs.stdout)
    assert "ExecInPkg(pkg='roc_launch_demo', exec='talker')" in ours.stdout


@pytest.mark.slow  # it needs the demo package built (the quick loop stays under 45 s)
def test_a_missing_file_or_package_is_one_line_listing_what_exists(demo, tmp_path: Path) -> None:
    env, _ = demo
    missing = roc("launch", PACKAGE, "demo.lanch.py", env=env)
    assert missing.returncode == 1
    assert missing.stderr.count("\n") == 1 and missing.stderr.startswith("roc: error: no file 'demo.lanch.py' in ")
    assert "did you mean 'demo.launch.py'?" in missing.stderr
    assert "launch/crash.launch.py, launch/demo.launch.py, launch/demo.launch.xml" in missing.stderr
    unknown = roc("launch", "roc_lunch_demo", "demo.launch.py", env=env)
    assert unknown.returncode == 1
    assert "package 'roc_lunch_demo' not found" in unknown.stderr and "did you mean roc_launch_demo?" in unknown.stderr
    malformed = roc("launch", PACKAGE, "demo.launch.py", "rate:=", env=env)
    assert malformed.returncode == 2 and "launch argument 'rate:=': expected NAME:=VALUE" in malformed.stderr
    nothing = roc("-C", str(tmp_path), "launch", "no_such_system", env=env)
    assert nothing.returncode == 2 and "'no_such_system' is not a launch file, and no roc.toml here" in nothing.stderr


@pytest.mark.slow  # over a second (the quick loop stays under 45 s)
def test_a_broken_launch_file_fails_as_in_ros2_launch(demo, tmp_path: Path) -> None:
    env, _ = demo
    broken = tmp_path / "broken.launch.py"
    broken.write_text("from launch import LaunchDescription\n\ndef generate_launch_description():\n"
                      "    return LaunchDescription([undefined_action()])\n")
    ours = roc("launch", "--log-base", str(tmp_path / "log"), str(broken), env=env)
    theirs = ros2("launch", str(broken), env=env)
    assert (ours.returncode, theirs.returncode) == (1, 1)

    def error(output: str) -> str:
        return output[output.index("[ERROR] [launch]: Caught exception in launch"):]

    assert error(ours.stdout + ours.stderr) == error(theirs.stdout + theirs.stderr)
    assert "NameError: name 'undefined_action' is not defined" in ours.stdout


HELLO = """from launch import LaunchDescription
from launch.actions import ExecuteProcess


def generate_launch_description():
    return LaunchDescription([ExecuteProcess(cmd=["echo", "hello"], name="hello", output="screen")])
"""


def _log_directory(output: str) -> Path:
    """The directory the launch library's "All log files can be found below DIR" line names."""
    found = re.search(r"All log files can be found below (\S+)", output)
    assert found, output
    return Path(found[1])


@pytest.mark.slow
def test_outside_a_workspace_the_logs_go_where_ros2_launch_writes_them(demo, tmp_path: Path) -> None:
    """Not into ./log of wherever the user stands: $ROS_LOG_DIR, else $ROS_HOME/log, else ~/.ros/log (the
    launch library's rule, compared with it in test_launch_logic.py), in a run directory named as ros2 launch
    names its own. In a workspace, its log/ as for builds."""
    env, _ = demo
    (tmp_path / "hello.launch.py").write_text(HELLO)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    base = tmp_path / "ros_log_dir"
    outputs = [subprocess.run([str(tool), "launch", "../hello.launch.py"], cwd=elsewhere,
                              env={**env, "ROS_LOG_DIR": str(base)}, capture_output=True, text=True, timeout=120)
               for tool in (ORACLE_VENV / "bin" / "ros2", BIN / "roc")]
    theirs, ours = (_log_directory(output.stdout + output.stderr) for output in outputs)
    assert theirs.parent == base
    assert ours.name == "launch" and ours.parent.parent == base  # the launch library's own log in launch/
    run = ours.parent
    assert re.fullmatch(r"\d{4}(-\d\d){5}-\d{6}-.+-\d+", run.name) and (base / "latest").resolve() == run
    assert "hello" in (run / "hello-1.log").read_text().splitlines() and (ours / "launch.log").is_file()
    assert list(elsewhere.iterdir()) == []

    workspace = tmp_path / "ws"
    (workspace / "src").mkdir(parents=True)
    inside = subprocess.run([str(BIN / "roc"), "launch", str(tmp_path / "hello.launch.py")], cwd=workspace / "src",
                            env=env, capture_output=True, text=True, timeout=120)
    assert _log_directory(inside.stdout).parent == (workspace / "log" / "latest_launch").resolve()
    assert (workspace / "log" / "latest_launch" / "hello-1.log").is_file()
