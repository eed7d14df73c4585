"""The bundled example workspace, built by roc, sourced in a fresh shell and run on a real ROS graph."""

from __future__ import annotations

import os
import shutil
import subprocess

import pytest
from helpers.build import (
    BIN,
    REPO,
    colcon,
    comparable_install_files,
    in_sourced_shell,
    package_dsv_files,
    ros_domain_id,
    sourced_values,
    stop_process,
    without_own_underlay,
)
from helpers.powershell import check_package_scripts, parse

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("example_workspace")]  # built once for the manual too


@pytest.fixture(scope="module")
def example(example_workspace):
    return example_workspace


def _packages_from_pypi() -> set[str]:
    """The ROS packages of this venv that came from PyPI's wheels: in the files of a distribution installed
    from an index (pip writes direct_url.json for one installed from a path, as the launch system of
    ../shared is; composition_interfaces, built with CMake there, belongs to no distribution)."""
    from importlib import metadata

    index = "share/ament_index/resource_index/packages/"
    return {str(file).rsplit("/", 1)[1] for distribution in metadata.distributions()
            if distribution.read_text("direct_url.json") is None
            for file in distribution.files or [] if index in str(file)}


def test_the_example_needs_only_what_the_set_up_takes_from_pypi():
    """The README's quick start builds the example on a fresh clone, where ../shared, and with it the
    launch system, may be missing: a dependency from there was a warning on the quick start's first
    build (demo_py's exec_depend on launch and launch_ros, for a launch file nothing used)."""
    from roc.workspace.load import discover_workspace
    from roc.workspace.underlay import missing_dependencies

    packages = discover_workspace(REPO / "workspaces" / "example")
    known = {package.name for package in packages} | _packages_from_pypi()
    assert "rclpy" in known and missing_dependencies(packages, known, ("build", "run")) == {}


@pytest.mark.distro
def test_cpp_executables_and_interfaces(example):
    ran = in_sourced_shell(example, "install/demo_tools/lib/demo_tools/filter_demo; demo_plain; "
                                    "python -c 'from demo_interfaces.msg import Reading; "
                                    "from demo_interfaces.srv import Scale; from demo_interfaces.action import Count; "
                                    "print(Reading(value=2.5).value)'")
    assert ran.returncode == 0, ran.stderr
    assert ran.stdout.splitlines() == ["demo_tools: filtered 1 2 3 4 -> 2.5", "demo_plain: sum 1 2 3 4 -> 10", "2.5"]


def test_powershell_scripts(example):
    """The interface package's ament environment hooks (library path, Python path...) too."""
    install = example / "install"
    for script in install.rglob("*.ps1"):
        parse(script.read_text())
    check_package_scripts(install, ["demo_interfaces", "demo_core", "demo_tools", "demo_py", "demo_plain", "tf2_msgs"],
                          merged=False)


@pytest.mark.distro
def test_python_node_messages_arrive(example):
    env = {"HOME": os.environ.get("HOME", "/tmp"), "PATH": f"{BIN}:/usr/bin:/bin", "ROS_DOMAIN_ID": ros_domain_id(5),
           "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST", "RMW_IMPLEMENTATION": "rmw_fastrtps_cpp"}
    source = "set -eu; source install/setup.bash; exec "
    listener = subprocess.Popen(["bash", "-c", source + "install/demo_py/lib/demo_py/reading_listener "
                                 "--ros-args -p max_count:=3"], cwd=example, env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True)
    publisher = subprocess.Popen(["bash", "-c", source + "install/demo_py/lib/demo_py/reading_publisher --ros-args "
                                  "--params-file install/demo_py/share/demo_py/config/params.yaml "
                                  "-p max_count:=100 -p rate:=10.0"], cwd=example, env=env,
                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        output, _ = listener.communicate(timeout=60)
    finally:
        for process in (listener, publisher):
            stop_process(process)
    assert listener.returncode == 0, output
    received = [line for line in output.splitlines() if "Received reading" in line]
    assert len(received) == 3 and all("celsius" in line for line in received), output


def test_frame_verbs_work_in_the_sourced_example(example):
    """The example's tf2_msgs is what roc frame needs: a static transform published and looked up."""
    env = {"HOME": os.environ.get("HOME", "/tmp"), "PATH": f"{BIN}:/usr/bin:/bin", "ROS_DOMAIN_ID": ros_domain_id(5),
           "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST", "RMW_IMPLEMENTATION": "rmw_fastrtps_cpp"}
    source = "set -eu; source install/setup.bash; exec "
    pub = subprocess.Popen(["bash", "-c", source + "roc frame pub map odom --x 1 --yaw 90 --degrees --no-daemon"], cwd=example,
                           env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        echo = subprocess.run(["bash", "-c", source + "roc frame echo map odom --once --no-daemon --timeout 30"],
                              cwd=example, env=env, capture_output=True, text=True, timeout=90)
    finally:
        stop_process(pub)
    assert echo.returncode == 0, echo.stderr
    assert echo.stdout.splitlines()[1:3] == ["- Translation: [1.000, 0.000, 0.000]",
                                             "- Rotation: in Quaternion (xyzw) [0.000, 0.000, 0.707, 0.707]"]


@pytest.mark.colcon
def test_same_install_tree_and_environment_as_colcon(example, tmp_path):
    theirs = tmp_path / "colcon"
    shutil.copytree(REPO / "workspaces" / "example" / "src", theirs / "src")
    result = colcon("build", "--parallel-workers", "2", cwd=theirs)
    assert result.returncode == 0, result.stdout + result.stderr
    assert comparable_install_files(example / "install") == comparable_install_files(theirs / "install")
    assert package_dsv_files(example / "install") == package_dsv_files(theirs / "install")
    ours_env = without_own_underlay(sourced_values(example))
    theirs_env = sourced_values(theirs, strict=False)
    theirs_env["LD_LIBRARY_PATH"] = theirs_env["LD_LIBRARY_PATH"].rstrip(":")  # colcon's empty entry
    assert {k: v.replace(str(example), "WS") for k, v in ours_env.items()} == \
        {k: v.replace(str(theirs), "WS") for k, v in theirs_env.items()}
