"""roc lifecycle and roc component on live nodes: rclpy lifecycle nodes, and a container (tests/nodes/container_node.py)
that serves composition_interfaces' services as rclcpp_components' does.

The installed ros2 CLI oracle has neither verb group; the expected texts are what ros2cli 0.32.2's
ros2lifecycle and ros2component print on the same graphs (checked side by side when these tests were
written, with both packages installed from ros2cli's jazzy sources)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest
from helpers.build import BIN, NODES, stop_process
from helpers.graph import component_prefix, graph_env, read_line, roc, start_nodes, stop_all, stop_daemon, wait_for

pytestmark = pytest.mark.slow

MANAGED = [{"name": "cam", "lifecycle": {}},
           {"name": "lidar", "namespace": "/robot", "lifecycle": {"fail": ["activate"]}},
           {"name": "_ghost", "lifecycle": {}}, {"name": "plain"}, {"name": "arm", "lifecycle": {}}]



@pytest.fixture(scope="module")
def managed(tmp_path_factory):
    env = graph_env(25, tmp_path_factory.mktemp("runtime"))
    processes = start_nodes([MANAGED], env)
    wait_for(lambda: roc("lifecycle", "nodes", "-a", env=env).stdout.split() == ["/_ghost", "/arm", "/cam",
                                                                                 "/robot/lidar"])
    yield env
    stop_daemon(env)
    stop_all(processes)


AS_ROS2 = [  # what ros2 lifecycle prints on this graph: (command, exit code, stdout, stderr)
    (("nodes",), 0, "/arm\n/cam\n/robot/lidar\n", ""),
    (("nodes", "-a"), 0, "/_ghost\n/arm\n/cam\n/robot/lidar\n", ""),
    (("nodes", "-c"), 0, "3\n", ""),
    (("get",), 0, "/arm: unconfigured [1]\n/cam: unconfigured [1]\n/robot/lidar: unconfigured [1]\n", ""),
    (("get", "/cam"), 0, "unconfigured [1]\n", ""),
    (("get", "cam"), 0, "unconfigured [1]\n", ""),
    (("get", "/plain"), 1, "", "Node not found"),
    (("get", "/_ghost"), 1, "", "Node not found"),
    (("get", "/_ghost", "--include-hidden-nodes"), 0, "unconfigured [1]\n", ""),
    (("list", "/cam"), 0, "- configure [1]\n\tStart: unconfigured\n\tGoal: configuring\n"
                          "- shutdown [5]\n\tStart: unconfigured\n\tGoal: shuttingdown\n", ""),
    (("list", "/plain"), 1, "", "Node not found"),
]


@pytest.mark.parametrize("command, code, stdout, stderr", AS_ROS2, ids=lambda v: " ".join(v) if isinstance(v, tuple)
                         else None)
def test_lifecycle_verbs_print_what_ros2_prints(managed, command, code, stdout, stderr):
    result = roc("lifecycle", *command, env=managed)
    assert (result.returncode, result.stdout) == (code, stdout), result.stderr
    assert stderr in result.stderr and (stderr or result.stderr == "")


def test_lifecycle_list_all_is_the_whole_transition_graph(managed):
    text = roc("lifecycle", "list", "/cam", "-a", env=managed).stdout
    assert text.startswith("- configure [1]\n\tStart: unconfigured\n\tGoal: configuring\n"
                           "- transition_success [10]\n\tStart: configuring\n\tGoal: inactive\n")
    assert text.count("\n- ") + 1 == 25 and text.endswith("- transition_error [62]\n\tStart: errorprocessing\n"
                                                          "\tGoal: finalized\n")


@pytest.mark.distro
def test_lifecycle_set_walks_a_node_through_its_states(managed):
    env = managed
    configured = roc("lifecycle", "set", "/arm", "configure", env=env)
    assert (configured.returncode, configured.stdout) == (0, "Transitioning successful\n")
    assert roc("lifecycle", "get", "/arm", env=env).stdout == "inactive [2]\n"
    unknown = roc("lifecycle", "set", "/arm", "nope", env=env)
    assert unknown.returncode == 1
    assert ("Unknown transition requested, available ones are:\n- cleanup [2]\n- activate [3]\n- shutdown [6]\n"
            in unknown.stderr)
    by_id = roc("lifecycle", "set", "/arm", "3", "--format", "json", env=env)
    assert json.loads(by_id.stdout) == {"node": "/arm", "transition": {"id": 3, "label": "activate"}, "success": True}
    assert json.loads(roc("lifecycle", "get", "/arm", "--format", "json", "--no-daemon", env=env).stdout) == [
        {"node": "/arm", "state": {"id": 3, "label": "active"}}]
    # a transition the node refuses: ros2 prints "Transitioning failed" on stderr (and exits 0; roc exits 1)
    assert roc("lifecycle", "set", "/robot/lidar", "1", env=env).returncode == 0
    refused = roc("lifecycle", "set", "/robot/lidar", "activate", env=env)
    assert (refused.returncode, refused.stdout, refused.stderr) == (1, "", "Transitioning failed\n")
    assert roc("lifecycle", "get", "/robot/lidar", env=env).stdout == "inactive [2]\n"


# ---- components ---------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def box(tmp_path_factory):
    """A running container /box, and the environment that finds the components."""
    pytest.importorskip("composition_interfaces.srv", reason="scripts/setup.sh builds composition_interfaces")
    root = tmp_path_factory.mktemp("components")
    env = graph_env(25, root / "runtime")
    env["AMENT_PREFIX_PATH"] = f"{component_prefix(root / 'prefix')}{os.pathsep}{env['AMENT_PREFIX_PATH']}"
    container = subprocess.Popen([sys.executable, str(NODES / "container_node.py"), "--ros-args", "-r", "__node:=box"],
                                 env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    assert read_line(container) == "ready\n"
    wait_for(lambda: roc("component", "list", env=env).stdout == "/box\n")
    yield env
    stop_daemon(env)
    stop_process(container)


def test_component_types_as_ros2(box):
    assert roc("component", "types", env=box).stdout == \
        "demo_components\n  demo_components::Talker\n  demo_components::Listener\n"
    assert roc("component", "types", "demo_components", env=box).stdout == \
        "demo_components::Talker\ndemo_components::Listener\n"
    assert roc("component", "types", "no_components", env=box).stdout == "\n"  # as ros2: one empty line
    missing = roc("component", "types", "nope", env=box)
    assert (missing.returncode, missing.stdout) == (1, "") and "Unable to find package 'nope'" in missing.stderr
    assert json.loads(roc("component", "types", "--format", "json", env=box).stdout) == {
        "demo_components": ["demo_components::Talker", "demo_components::Listener"]}


def test_component_load_list_unload_as_ros2(box):
    env = box
    assert roc("component", "list", "/box", env=env).stdout == ""
    missing = roc("component", "list", "/nope", env=env)
    assert missing.returncode == 1 and "Unable to find container node '/nope'" in missing.stderr
    loaded = roc("component", "load", "/box", "demo_components", "demo_components::Talker", env=env)
    assert loaded.stdout == "Loaded component 1 into '/box' container node as '/talker'\n", loaded.stderr
    quiet = roc("component", "load", "/box", "demo_components", "demo_components::Listener", "-q",
                "--node-namespace", "/ns", env=env)
    assert quiet.stdout == "2  /ns/listener\n"
    named = roc("component", "load", "/box", "demo_components", "demo_components::Talker", "-n", "talker2",
                "-r", "chatter:=news", "-p", "rate:=2.5", "-p", "label:=left", "--log-level", "debug", env=env)
    assert named.stdout == "Loaded component 3 into '/box' container node as '/talker2'\n", named.stderr
    assert roc("component", "list", env=env).stdout == "/box\n  1  /talker\n  2  /ns/listener\n  3  /talker2\n"
    assert roc("component", "list", "/box", env=env).stdout == "1  /talker\n2  /ns/listener\n3  /talker2\n"
    assert roc("component", "list", "--containers-only", env=env).stdout == "/box\n"
    assert json.loads(roc("component", "list", "--format", "json", env=env).stdout)[0]["components"][2] == \
        {"uid": 3, "name": "/talker2"}
    # the request's remapping and parameters reached the node
    wait_for(lambda: "/news: std_msgs/msg/String" in roc("node", "info", "/talker2", env=env).stdout)
    assert roc("param", "get", "/talker2", "rate", env=env).stdout == "Double value is: 2.5\n"
    assert roc("param", "get", "/talker2", "label", env=env).stdout == "String value is: left\n"

    for plugin, package, reason in (("demo_components::Nope", "demo_components",
                                     "Failed to find class with the requested plugin name."),
                                    ("demo_components::Talker", "nopkg",
                                     "Could not find requested resource in ament index")):
        refused = roc("component", "load", "/box", package, plugin, env=env)
        assert refused.returncode == 1 and f"Failed to load component: {reason}" in refused.stderr
    unloaded = roc("component", "unload", "/box", "1", env=env)
    assert unloaded.stdout == "Unloaded component 1 from '/box' container node\n"
    assert roc("component", "unload", "/box", "2", "-q", env=env).stdout == "2\n"
    gone = roc("component", "unload", "/box", "9", env=env)
    assert gone.returncode == 1
    assert "Failed to unload component 9 from '/box' container node\n    No node found with unique_id: 9" in gone.stderr
    assert roc("component", "list", env=env).stdout == "/box\n  3  /talker2\n"


def test_component_standalone_runs_its_own_container_until_stopped(box):
    env = box
    standalone = subprocess.Popen([str(BIN / "roc"), "component", "standalone", "demo_components",
                                   "demo_components::Talker", "-c", "solo", "-n", "solo_talker"], env=env,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        wait_for(lambda: roc("component", "list", "/solo", env=env).stdout == "1  /solo_talker\n")
    finally:
        standalone.terminate()  # forwarded to the container as its Ctrl+C
        code = standalone.wait(timeout=20)
    assert code == 0
    wait_for(lambda: "/solo" not in roc("node", "list", env=env).stdout.split())
    failed = roc("component", "standalone", "demo_components", "demo_components::Nope", "-c", "solo2", env=env)
    assert failed.returncode == 0  # the container's exit code, as ros2's
    assert ("Failed to load component: Failed to find class with the requested plugin name., interrupting "
            "container node\n") in failed.stderr
