"""``roc work create --node-name`` of an ament_cmake package: its rclcpp node builds on the C++ stack
(tests/helpers/cpp.py), and, run from a shell that sourced only the new workspace, publishes what roc
topic echo reads."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from helpers.build import BIN, ros_domain_id, ros_env, stop_process
from helpers.cpp import require_stack, sourced
from helpers.graph import roc

pytestmark = [pytest.mark.slow, pytest.mark.cpp]

SLOT = 46


def test_a_created_cpp_node_builds_on_the_stack_and_publishes(tmp_path: Path) -> None:
    require_stack()
    shell = {k: v for k, v in ros_env(ROS_DOMAIN_ID=ros_domain_id(SLOT), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
                                      XDG_RUNTIME_DIR=str(tmp_path)).items()
             if k not in ("AMENT_PREFIX_PATH", "LD_LIBRARY_PATH", "_ROS_WHEELS_BOOTSTRAP_COMPLETE")}
    env = sourced(shell)
    workspace = tmp_path / "ws"
    (workspace / "src").mkdir(parents=True)
    created = subprocess.run([str(BIN / "roc"), "work", "create", "my_cpp", "--build-type", "ament_cmake",
                              "--node-name", "my_node", "--destination-directory", "src"],
                             cwd=workspace, env=env, capture_output=True, text=True)
    assert created.returncode == 0, created.stderr
    built = subprocess.run([str(BIN / "roc"), "work", "build"], cwd=workspace, env=env, capture_output=True,
                           text=True, timeout=600)
    assert built.returncode == 0, built.stdout + built.stderr

    # a new shell that sources the workspace alone: it chains the stack and the wheels it was built on
    user = sourced(shell, workspace / "install" / "setup.bash")
    node = subprocess.Popen([str(workspace / "install" / "my_cpp" / "lib" / "my_cpp" / "my_node")], env=user,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        echo = roc("topic", "echo", "/chatter", "--once", "--no-daemon", env=user, timeout=30)
        assert echo.stdout.startswith("data: 'Hello from my_cpp: "), echo.stdout + echo.stderr
    finally:
        stop_process(node)
