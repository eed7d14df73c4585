"""roc launch FILE --explain: what the launch library would start, nothing started, and then exactly that
starts (command line, working directory, environment and parameter files, compared with /proc of the
started processes); --show-args: the arguments of the file and of every file it includes, recursively,
each with the file that declares it, beside ros2 launch --show-args, which cannot follow an include whose
path needs an argument's value."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import pytest
from helpers.graph import install_oracle, roc, ros2, stop_daemon
from helpers.launch import (
    demo_env,
    kill_leftovers,
    nodes,
    processes_with,
    roc_launch,
    skip_without_launch_library,
    wait_until,
)
from helpers.proc import as_proc_shows, proc_argv, proc_environ

pytestmark = pytest.mark.slow
SYSTEM = """
import os
from launch import LaunchDescription
from launch.actions import (DeclareLaunchArgument, ExecuteProcess, GroupAction, IncludeLaunchDescription,
                            SetEnvironmentVariable, TimerAction, UnsetEnvironmentVariable)
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration, ThisLaunchFileDir
from launch_ros.actions import LifecycleNode, Node, PushRosNamespace


def generate_launch_description():
    robot = LaunchConfiguration('robot')
    return LaunchDescription([
        DeclareLaunchArgument('robot', default_value='robot1', description='the robot'),
        SetEnvironmentVariable('ROC_TEST_SITE', ['lab-', robot]),
        UnsetEnvironmentVariable('ROC_TEST_GONE'),
        Node(package='roc_launch_demo', executable='talker', name='talker', namespace=robot,
             parameters=[{'rate': 4.0, 'greeting': robot}, os.path.join(os.path.dirname(__file__), 'talker.yaml')],
             remappings=[('chatter', 'news')], additional_env={'ROC_TEST_ROLE': 'talker'}),
        GroupAction([PushRosNamespace('group'),
                     Node(package='roc_launch_demo', executable='listener', remappings=[('chatter', 'news')])]),
        LifecycleNode(package='roc_launch_demo', executable='listener', name='managed', namespace=''),
        TimerAction(period=1.0, actions=[ExecuteProcess(cmd=['sleep', '60'], cwd=os.path.dirname(__file__),
                                                        name='sleeper')]),
        IncludeLaunchDescription(PythonLaunchDescriptionSource([ThisLaunchFileDir(), '/server.launch.py']),
                                 launch_arguments={'delay': '0.5'}.items()),
    ])
"""
SERVER = """
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument('delay', default_value='2.0', description='seconds before the service'),
        Node(package='roc_launch_demo', executable='server', name='map_server',
             parameters=[{'delay': LaunchConfiguration('delay')}]),
    ])
"""


@pytest.fixture(scope="module")
def demo(tmp_path_factory, launch_demo_prefix):
    skip_without_launch_library()
    prefix = launch_demo_prefix
    env = demo_env(55, tmp_path_factory.mktemp("runtime"), prefix, ROC_TEST_GONE="1")
    yield env, prefix
    stop_daemon(env)
    kill_leftovers(str(prefix))


def _files(directory: Path) -> Path:
    (directory / "system.launch.py").write_text(SYSTEM)
    (directory / "server.launch.py").write_text(SERVER)
    (directory / "talker.yaml").write_text("/**:\n  ros__parameters:\n    volume: 11\n")
    return directory / "system.launch.py"


def _started(output: str) -> dict[str, int]:
    return {name: int(pid) for name, pid in re.findall(r"\[INFO\] \[([\w-]+)\]: process started with pid \[(\d+)\]",
                                                       output)}






def _yaml(path: str):
    import yaml

    return yaml.safe_load(Path(path).read_text())


def test_explain_lists_exactly_what_a_start_then_runs(demo, tmp_path: Path) -> None:
    env, prefix = demo
    path = _files(tmp_path)
    explained = roc("-C", str(tmp_path), "launch", str(path), "robot:=r5", "--explain", "--format", "json", env=env)
    assert explained.returncode == 0, explained.stderr
    entries = {entry["name"]: entry for entry in json.loads(explained.stdout)}
    assert list(entries) == ["talker-1", "listener-2", "listener-3", "server-4", "sleeper-5"]
    assert not processes_with(str(prefix)) and not processes_with(str(tmp_path))  # nothing started
    talker = entries["talker-1"]
    assert talker["env"] == {"ROC_TEST_ROLE": "talker", "ROC_TEST_SITE": "lab-r5"} and talker["unset"] == ["ROC_TEST_GONE"]
    assert talker["remappings"] == {"__node": "talker", "__ns": "/r5", "chatter": "news"}
    written, user_file = talker["parameter_files"]
    assert talker["written_parameters"] == {written: {"/r5/talker": {"ros__parameters": {"rate": 4.0, "greeting": "r5"}}}}
    assert user_file == str(tmp_path / "talker.yaml")
    assert entries["listener-2"]["remappings"] == {"__ns": "/group", "chatter": "news"}
    assert entries["listener-3"]["remappings"] == {"__node": "managed", "__ns": "/"}
    assert entries["sleeper-5"]["cwd"] == str(tmp_path) and entries["sleeper-5"]["command"] == ["sleep", "60"]
    assert list(entries["server-4"]["written_parameters"].values()) == [
        {"/**": {"ros__parameters": {"delay": 0.5}}}]  # the include's argument

    launcher = roc_launch(str(path), "robot:=r5", env=env, log=tmp_path / "roc.log")
    try:
        launcher.wait_for_output("[sleeper-5]: process started with pid", timeout=60)
        started = _started(launcher.output())
        assert sorted(started) == sorted(entries)
        roc_environ = proc_environ(launcher.pid)
        for name, entry in entries.items():
            pid = started[name]
            shown = as_proc_shows(entry["command"])
            words = len(shown)  # a forked process takes on its command line a moment after its start
            cmdline = wait_until(lambda p=pid, n=words: len(argv := proc_argv(p)) == n and argv, 10, f"{name}'s argv")
            for index, word in enumerate(shown):  # a start writes its parameter files anew, under new names
                if word in entry["written_parameters"]:
                    assert _yaml(cmdline[index]) == entry["written_parameters"][word]
                    cmdline[index] = word
            assert cmdline == shown, name
            assert os.readlink(f"/proc/{pid}/cwd") == entry["cwd"], name
            expected = {**roc_environ, **entry["env"]}
            for variable in entry["unset"]:
                expected.pop(variable)
            assert {k: v for k, v in proc_environ(pid).items() if k != "ROC_LAUNCH_ID"} == expected, name
    finally:
        assert launcher.stop() == 0, launcher.output()
    assert not kill_leftovers(str(tmp_path))


def test_explain_text_names_each_process_its_command_and_what_it_adds(demo, tmp_path: Path) -> None:
    env, prefix = demo
    path = _files(tmp_path)
    explained = roc("-C", str(tmp_path), "launch", str(path), "--explain", env=env)
    assert explained.returncode == 0, explained.stderr
    text = re.sub(r"launch_params_\w+", "launch_params_X", explained.stdout)
    lib = prefix / "lib" / "roc_launch_demo"
    assert text.startswith(
        f"{path}: 5 processes\n"
        "talker-1:\n"
        f"    {lib}/talker --ros-args -r __node:=talker -r __ns:=/robot1 --params-file /tmp/launch_params_X "
        f"--params-file {tmp_path}/talker.yaml -r chatter:=news\n"
        "    environment: ROC_TEST_ROLE=talker ROC_TEST_SITE=lab-robot1 -ROC_TEST_GONE\n"
        f"    parameters (in a file the launch library writes at each start): greeting=\"robot1\" rate=4.0\n"
        f"    parameters from {tmp_path}/talker.yaml\n"), text
    assert "sleeper-5:\n    sleep 60\n    environment: ROC_TEST_SITE=lab-robot1 -ROC_TEST_GONE\n" in text
    assert not processes_with(str(prefix)) and not nodes(env) & {"/robot1/talker", "/map_server"}


def test_explain_of_a_broken_launch_file_is_its_error(demo, tmp_path: Path) -> None:
    env, _ = demo
    broken = tmp_path / "broken.launch.py"
    broken.write_text("raise RuntimeError('no robot here')\n")
    result = roc("launch", str(broken), "--explain", env=env)
    assert result.returncode == 1 and result.stdout == ""
    assert result.stderr == (f"roc: error: {broken}: Caught multiple exceptions when trying to load file of format "
                             "[py]: RuntimeError: no robot here; InvalidFrontendLaunchFileError: The launch file may "
                             "have a syntax error, or its format is unknown\n")


TOP = """
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription
from launch.conditions import IfCondition
from launch.launch_description_sources import AnyLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration, ThisLaunchFileDir


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument('robot', default_value='robot1', description='the robot'),
        DeclareLaunchArgument('stack', default_value='nav', description='which stack to bring up'),
        DeclareLaunchArgument('sim', default_value='false', description='simulate the sensors'),
        IncludeLaunchDescription(AnyLaunchDescriptionSource(
            [ThisLaunchFileDir(), '/', LaunchConfiguration('stack'), '.launch.xml'])),
        IncludeLaunchDescription(AnyLaunchDescriptionSource([ThisLaunchFileDir(), '/sim.launch.yaml']),
                                 condition=IfCondition(LaunchConfiguration('sim'))),
    ])
"""
NAV = """<launch>
  <arg name="map" default="$(var robot).yaml" description="the map to load"/>
  <include file="$(dirname)/sensors.launch.yaml">
    <arg name="rate" value="20.0"/>
  </include>
</launch>
"""
SENSORS = """launch:
- arg: {name: rate, default: "10.0", description: scan rate in Hz}
- arg: {name: frame, default: laser, description: the scan's frame}
"""
SIM = """launch:
- arg: {name: world, default: office, description: the simulated world}
"""


def test_show_args_lists_the_arguments_of_every_included_file(demo, tmp_path: Path) -> None:
    env, _ = demo
    for name, text in (("top.launch.py", TOP), ("nav.launch.xml", NAV), ("sensors.launch.yaml", SENSORS),
                       ("sim.launch.yaml", SIM)):
        (tmp_path / name).write_text(text)
    top = tmp_path / "top.launch.py"
    shown = roc("launch", str(top), "--show-args", "--format", "json", env=env)
    assert shown.returncode == 0, shown.stderr
    found = {a["name"]: a for a in json.loads(shown.stdout)["arguments"]}
    assert [(name, a["file"], a["included_by"], a["default"], a["value"], a["conditional"]) for name, a in found.items()] == [
        ("robot", str(top), [], "'robot1'", "robot1", False),
        ("stack", str(top), [], "'nav'", "nav", False),
        ("sim", str(top), [], "'false'", "false", False),
        ("map", str(tmp_path / "nav.launch.xml"), [str(top)], "LaunchConfig('robot') + '.yaml'", "robot1.yaml", False),
        ("rate", str(tmp_path / "sensors.launch.yaml"), [str(top), str(tmp_path / "nav.launch.xml")], "'10.0'",
         "10.0", False),
        ("frame", str(tmp_path / "sensors.launch.yaml"), [str(top), str(tmp_path / "nav.launch.xml")], "'laser'",
         "laser", False),
        ("world", str(tmp_path / "sim.launch.yaml"), [str(top)], "'office'", "office", True)]
    assert found["rate"]["set_by"] == {"file": str(tmp_path / "nav.launch.xml"), "value": "20.0"}
    assert found["map"]["description"] == "the map to load"
    # a value given on the command line is followed: another stack, whose file does not exist
    other = roc("launch", str(top), "stack:=arm", "--show-args", "--format", "json", env=env)
    assert [a["name"] for a in json.loads(other.stdout)["arguments"]] == ["robot", "stack", "sim", "world"]
    assert json.loads(other.stdout)["unknown"] == [
        f"{top}: cannot follow the include of ThisLaunchFileDir() + '/' + LaunchConfig('stack') + '.launch.xml' "
        f"({tmp_path}/arm.launch.xml): Caught multiple exceptions when trying to load file of format [xml]: "
        f"FileNotFoundError: [Errno 2] No such file or directory: '{tmp_path}/arm.launch.xml'"]

    text = roc("launch", str(top), "--show-args", env=env).stdout
    assert (f"    'rate':\n        scan rate in Hz\n        (default: '10.0')\n"
            f"        (declared in {tmp_path}/sensors.launch.yaml, included by nav.launch.xml < top.launch.py)\n"
            "        (set to '20.0' by the include in nav.launch.xml: a value given on the command line does not "
            "reach it)\n") in text
    assert "    'world':*\n" in text and text.endswith("\n* argument(s) which are only used if specific conditions occur\n")
    reason = install_oracle(launch=True)
    if reason:
        pytest.skip(f"no ros2 launch oracle: {reason}")
    theirs = ros2("launch", "--show-args", str(top), env=env)
    assert theirs.returncode == 0, theirs.stderr
    blocks = theirs.stdout.rstrip("\n").split("\n\n")
    assert len(blocks) == 4 and "'map'" not in theirs.stdout  # ros2 launch cannot follow the include of nav
    assert text.startswith("\n\n".join(blocks) + "\n")  # the top file's arguments: as ros2 launch prints them
