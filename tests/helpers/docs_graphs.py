"""The live ROS graphs the manual's examples show (``<!-- example: DIR, graph NAME -->``, see
tests/helpers/docs_examples.py), started by tests/docs/test_docs_live_graph.py in a ROS domain of its own.

    demo        the example workspace's reading_publisher and reading_listener (with its params.yaml),
                and /motor_controller: a std_srvs/srv/SetBool service ~/enable, a max_speed parameter
                and the test_msgs/action/Fibonacci server /fibonacci (tests/nodes/graph_node.py)
    doctor      two nodes named /talker, /scan best effort to /listener's reliable subscription,
                /chatter without subscriber, /cmd without publisher
    robot       the managed nodes /cam and /robot/lidar (whose activate fails); tf from /robot_state
                (map->odom and base_link->laser static, odom->base_link at 20 Hz) and /camera_driver
                (camera->lens at 10 Hz, tests/nodes/tf_node.py); the component container /box, with
                demo_components' Talker and Listener installed (the lifecycle, frame and component
                pages: none of their verbs sees the others' nodes)
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

from helpers.build import NODES, stop_process
from helpers.graph import component_prefix, roc, start_nodes, wait_for

READING_NODES = ("reading_publisher", "reading_listener")


def _motor_controller() -> dict:
    """The Fibonacci server takes 0.1 s a step, as a real one would: with none, its last feedback and its
    result come at once, and which a client handles first is chance (the page shows both feedbacks)."""
    return {"name": "motor_controller", "services": [{"name": "~/enable", "type": "std_srvs/srv/SetBool"}],
            "parameters": {"max_speed": 1.5}, "actions": [{"name": "/fibonacci", "step_seconds": 0.1}]}


def _readings(workspace: Path, env: dict[str, str], _root: Path) -> list[subprocess.Popen]:
    params = workspace / "install" / "demo_py" / "share" / "demo_py" / "config" / "params.yaml"
    return [subprocess.Popen([str(workspace / "install" / "demo_py" / "lib" / "demo_py" / name), "--ros-args",
                              "--params-file", str(params)], env=env, stdin=subprocess.DEVNULL,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            for name in READING_NODES]


def _demo(workspace: Path, env: dict[str, str], root: Path) -> list[subprocess.Popen]:
    return _readings(workspace, env, root) + start_nodes([[_motor_controller()]], env)


def _doctor(_workspace: Path, env: dict[str, str], _root: Path) -> list[subprocess.Popen]:
    string = {"type": "std_msgs/msg/String"}
    return start_nodes([
        [{"name": "talker", "publishers": [{"topic": "scan", **string, "reliability": "best_effort"},
                                           {"topic": "chatter", **string}]}],
        [{"name": "talker"},
         {"name": "listener", "subscribers": [{"topic": "scan", **string}, {"topic": "cmd", **string}]}]], env)


def _lifecycle(_workspace: Path, env: dict[str, str], _root: Path) -> list[subprocess.Popen]:
    return start_nodes([[{"name": "cam", "lifecycle": {}},
                         {"name": "lidar", "namespace": "/robot", "lifecycle": {"fail": ["activate"]}}]], env)


def _tf(_workspace: Path, env: dict[str, str], _root: Path) -> list[subprocess.Popen]:
    processes = [subprocess.Popen([sys.executable, str(NODES / "tf_node.py"), mode, "--ros-args", "-r",
                                   f"__node:={name}"], env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                  stderr=subprocess.DEVNULL, text=True)
                 for mode, name in (("publish", "robot_state"), ("camera", "camera_driver"))]
    for process in processes:
        assert process.stdout is not None and process.stdout.readline().strip() == "ready"
    return processes


def _components(_workspace: Path, env: dict[str, str], root: Path) -> list[subprocess.Popen]:
    env["AMENT_PREFIX_PATH"] = os.pathsep.join([str(component_prefix(root / "prefix")), env.get("AMENT_PREFIX_PATH", "")])
    container = subprocess.Popen([sys.executable, str(NODES / "container_node.py"), "--ros-args", "-r", "__node:=box"],
                                 env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                 text=True)
    assert container.stdout is not None and container.stdout.readline().strip() == "ready"
    return [container]


def _robot(workspace: Path, env: dict[str, str], root: Path) -> list[subprocess.Popen]:
    return [*_components(workspace, env, root), *_lifecycle(workspace, env, root), *_tf(workspace, env, root)]


# name -> (start it: (built example workspace, environment, a directory of its own) -> processes,
#          the nodes that must be seen before an example runs)
GRAPHS: dict[str, tuple[Callable[[Path, dict[str, str], Path], list[subprocess.Popen]], set[str]]] = {
    "demo": (_demo, {"/reading_publisher", "/reading_listener", "/motor_controller"}),
    "doctor": (_doctor, {"/talker", "/listener"}),
    "robot": (_robot, {"/cam", "/robot/lidar", "/robot_state", "/camera_driver", "/box"}),
}


class LiveGraph:
    """One graph of GRAPHS, running until ``stop``; roc's daemon of its environment is stopped with it."""

    def __init__(self, name: str, workspace: Path, env: dict[str, str], root: Path):
        start, self.nodes = GRAPHS[name]
        self.name, self.env = name, env
        self.processes = start(workspace, env, root)
        try:
            wait_for(lambda: self.nodes <= set(roc("node", "list", env=env).stdout.split()), timeout=60)
            # the first verb answered in its own process and started the daemon: the pages show a warm one
            wait_for(lambda: '"ready": true' in roc("daemon", "status", "--format", "json", env=env).stdout,
                     timeout=60)
        except BaseException:
            self.stop()
            raise

    def stop(self) -> None:
        roc("daemon", "stop", env=self.env)
        for process in self.processes:
            stop_process(process)
