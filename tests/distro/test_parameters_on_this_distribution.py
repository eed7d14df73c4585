"""roc param on the distribution that runs the tests: set, get, a wrong type refused, delete, a dump loaded
back. (The node's own words for a wrong type differ: Jazzy's rclpy names the types, 'Type.DOUBLE', Kilted's
gives their numbers, '3'; roc passes them on as ros2 param does, so only the start is the same.)"""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers.graph import graph_env, roc, start_nodes, stop_all, stop_daemon

pytestmark = [pytest.mark.distro, pytest.mark.slow]
MOTOR = {"name": "motor", "parameters": {"max_speed": 1.5, "wheels": ["left", "right"]}, "undeclared_parameters": True}


@pytest.fixture(scope="module")
def motor(tmp_path_factory):
    env = graph_env(52, tmp_path_factory.mktemp("runtime"))
    processes = start_nodes([[MOTOR]], env)
    yield env
    stop_daemon(env)
    stop_all(processes)


def test_parameters_set_get_delete_and_load(motor, tmp_path: Path) -> None:
    env = motor
    result = roc("param", "set", "/motor", "max_speed", "2.5", "gain", "[1, 2]", env=env)
    assert (result.returncode, result.stdout) == (0, "Set parameter max_speed successful\nSet parameter gain successful\n")
    assert roc("param", "get", "/motor", "max_speed", env=env).stdout == "Double value is: 2.5\n"
    assert roc("param", "get", "/motor", "gain", env=env).stdout == "Integer values are: [1, 2]\n"
    wrong = roc("param", "set", "/motor", "max_speed", "fast", env=env)
    assert (wrong.returncode, wrong.stdout) == (1, "")
    assert wrong.stderr.startswith("Setting parameter failed: Wrong parameter type, expected "), wrong.stderr
    deleted = roc("param", "delete", "/motor", "gain", env=env)
    assert (deleted.returncode, deleted.stdout) == (0, "Deleted parameter successfully\n")
    dump = tmp_path / "motor.yaml"
    dump.write_text(roc("param", "dump", "/motor", env=env).stdout.replace("2.5", "3.5"))
    loaded = roc("param", "load", "/motor", str(dump), env=env)
    assert loaded.returncode == 0 and "Set parameter max_speed successful\n" in loaded.stdout, loaded.stderr
    assert roc("param", "get", "/motor", "max_speed", env=env).stdout == "Double value is: 3.5\n"
