"""The C++ stack as ``bash scripts/setup.sh --with-cpp`` leaves it (rclcpp and the demos' C++ nodes built by
roc on the Jazzy wheels, tests/helpers/cpp.py): sourced, it lists its own libraries before the wheels'
and every library its programs need resolves; an unchanged set-up has nothing to build."""

from __future__ import annotations

import subprocess
import sys

import pytest
from helpers.build import BIN, ros_env
from helpers.cpp import STACK, library_path, require_stack, sourced

pytestmark = [pytest.mark.slow, pytest.mark.cpp]

PROGRAMS = [("demo_nodes_cpp", "talker"), ("rclcpp_components", "component_container"),
            ("action_tutorials_cpp", "fibonacci_action_server"), ("lifecycle", "lifecycle_talker")]


def clean_shell() -> dict[str, str]:
    """A user's shell with nothing ROS sourced and no library path of the venv's bootstrapper."""
    return {key: value for key, value in ros_env().items()
            if key not in ("AMENT_PREFIX_PATH", "LD_LIBRARY_PATH", "PYTHONPATH", "_ROS_WHEELS_BOOTSTRAP_COMPLETE")}


def test_the_sourced_stack_lists_its_libraries_before_the_wheels_and_its_underlay_s(tmp_path) -> None:
    install = require_stack()
    libraries = library_path(sourced(clean_shell()))
    stack, underlay, wheels = (libraries.index(str(install / "rclcpp" / "lib")),
                               libraries.index(str(STACK / "underlay" / "install" / "console_bridge" / "lib")),
                               libraries.index(f"{sys.prefix}/lib"))
    assert stack < underlay < wheels, libraries
    assert any(entry.endswith("site-packages/ros_rcl.libs") for entry in libraries), libraries


@pytest.mark.parametrize("package, program", PROGRAMS, ids=lambda value: value)
def test_every_library_of_a_cpp_program_resolves_in_a_sourced_shell(package: str, program: str) -> None:
    install = require_stack()
    path = install / package / "lib" / package / program
    linked = subprocess.run(["ldd", str(path)], env=sourced(clean_shell()), capture_output=True, text=True)
    assert linked.returncode == 0, linked.stderr
    assert "not found" not in linked.stdout, linked.stdout
    assert f"librclcpp.so => {install}/rclcpp/lib/librclcpp.so" in linked.stdout  # the stack's, not another's


def test_an_unchanged_stack_has_nothing_to_build() -> None:
    require_stack()
    env = sourced(clean_shell(), STACK / "underlay" / "install" / "setup.bash")
    explained = subprocess.run([str(BIN / "roc"), "-C", str(STACK / "stack"), "work", "build", "--explain",
                                "--allow-overriding", "composition_interfaces",
                                "--cmake-args", "-DCMAKE_BUILD_TYPE=Release", "-DBUILD_TESTING=OFF"],
                               env=env, capture_output=True, text=True, timeout=60)
    assert explained.returncode == 0, explained.stderr
    lines = explained.stdout.splitlines()
    assert len(lines) == 17 and all(line.endswith(": up to date") for line in lines), explained.stdout
