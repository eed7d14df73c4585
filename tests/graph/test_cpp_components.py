"""roc component against rclcpp_components' real containers (component_container and
component_container_mt, built from source in the C++ stack) with the demos' composition components.
The expected texts are ros2component's (ros2cli 0.32.2) on the same requests, as
tests/graph/test_lifecycle_and_component.py holds them for the Python stand-in container."""

from __future__ import annotations

import json
import subprocess

import pytest
from helpers.build import BIN, stop_process
from helpers.cpp import require_stack, sourced
from helpers.graph import graph_env, roc, stop_daemon, wait_for

pytestmark = [pytest.mark.slow, pytest.mark.cpp]

SLOT = 29
COMPOSITION = ["composition::Talker", "composition::Listener", "composition::NodeLikeListener", "composition::Server",
               "composition::Client"]


@pytest.fixture(scope="module")
def env(tmp_path_factory):
    require_stack()
    environment = sourced(graph_env(SLOT, tmp_path_factory.mktemp("runtime")))
    yield environment
    stop_daemon(environment)


@pytest.fixture(params=["component_container", "component_container_mt"])
def container(request, env):
    program = require_stack() / "rclcpp_components" / "lib" / "rclcpp_components" / request.param
    process = subprocess.Popen([str(program), "--ros-args", "-r", "__node:=box"], env=env,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        wait_for(lambda: roc("component", "list", env=env).stdout == "/box\n", timeout=30)
        yield env
    finally:
        stop_process(process)
        wait_for(lambda: "/box" not in roc("node", "list", env=env).stdout.split(), timeout=30)


def test_component_types_lists_the_installed_composition_components_as_ros2(env):
    types = roc("component", "types", "composition", env=env)
    assert types.returncode == 0, types.stderr
    assert types.stdout.splitlines() == COMPOSITION
    every = roc("component", "types", env=env).stdout
    assert "composition\n" + "".join(f"  {name}\n" for name in COMPOSITION) in every
    assert json.loads(roc("component", "types", "--format", "json", env=env).stdout)["composition"] == COMPOSITION


def test_components_load_list_and_unload_in_a_real_container(container):
    env = container
    loaded = roc("component", "load", "/box", "composition", "composition::Talker", env=env)
    assert loaded.stdout == "Loaded component 1 into '/box' container node as '/talker'\n", loaded.stderr
    quiet = roc("component", "load", "/box", "composition", "composition::Listener", "-q", "-n", "ear",
                "-r", "chatter:=news", env=env)
    assert quiet.stdout == "2  /ear\n", quiet.stderr
    assert roc("component", "list", env=env).stdout == "/box\n  1  /talker\n  2  /ear\n"
    assert roc("component", "list", "/box", env=env).stdout == "1  /talker\n2  /ear\n"
    # the loaded talker publishes, and the listener's remapping reached it
    echo = roc("topic", "echo", "/chatter", "--once", env=env, timeout=30)
    assert echo.stdout.startswith("data: 'Hello World: "), echo.stderr
    wait_for(lambda: "/news: std_msgs/msg/String" in roc("node", "info", "/ear", env=env).stdout)

    refused = roc("component", "load", "/box", "composition", "composition::Nope", env=env)
    assert refused.returncode == 1
    assert "Failed to load component: Failed to find class with the requested plugin name." in refused.stderr
    unloaded = roc("component", "unload", "/box", "1", env=env)
    assert unloaded.stdout == "Unloaded component 1 from '/box' container node\n", unloaded.stderr
    gone = roc("component", "unload", "/box", "9", env=env)
    assert gone.returncode == 1
    assert "Failed to unload component 9 from '/box' container node\n    No node found with unique_id: 9" in gone.stderr
    assert roc("component", "list", env=env).stdout == "/box\n  2  /ear\n"


def test_component_standalone_runs_a_real_container_until_stopped(env):
    standalone = subprocess.Popen([str(BIN / "roc"), "component", "standalone", "composition", "composition::Talker",
                                   "-c", "solo", "-n", "solo_talker"], env=env,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        wait_for(lambda: roc("component", "list", "/solo", env=env).stdout == "1  /solo_talker\n", timeout=30)
    finally:
        standalone.terminate()  # forwarded to the container as its Ctrl+C
        code = standalone.wait(timeout=20)
    assert code == 0
    wait_for(lambda: "/solo" not in roc("node", "list", env=env).stdout.split())
