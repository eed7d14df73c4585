"""A package whose CMake configure fails for want of a test tool (ament_lint_auto, a linter) or of a test
dependency the workspace has but never built: the console's line of the failed package says how to go
on. The error texts are CMake's own, as ament_cmake 2.5.4 (Jazzy's wheels) printed them."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from helpers.build import DISTRO, add_cmake_package, colcon, roc

from roc.builder.failure_hints import failure_hint
from roc.workspace.package import Package

# find_package(ament_lint_auto REQUIRED) in `if(BUILD_TESTING)`, ament_lint_auto not installed
LINT_AUTO_MISSING = """\
CMake Error at CMakeLists.txt:5 (find_package):
  By not providing "Findament_lint_auto.cmake" in CMAKE_MODULE_PATH this
  project has asked CMake to find a package configuration file provided by
  "ament_lint_auto", but CMake did not find one.

  Could not find a package configuration file provided by "ament_lint_auto"
  with any of the following names:

    ament_lint_autoConfig.cmake
    ament_lint_auto-config.cmake

  Add the installation prefix of "ament_lint_auto" to CMAKE_PREFIX_PATH or
  set "ament_lint_auto_DIR" to a directory containing one of the above files.
  If "ament_lint_auto" provides a separate development package or SDK, be
  sure it has been installed.
"""

# std_msgs of ros2/common_interfaces (jazzy): rosidl_generate_interfaces(... ADD_LINTER_TESTS) with
# ament_cmake_cppcheck installed (a wheel) but not the ament_cppcheck linter it runs
CPPCHECK_MISSING = """\
CMake Error at /work/main/.venv/share/ament_cmake_cppcheck/cmake/ament_cppcheck.cmake:45 (message):
  ament_cppcheck() could not find program 'ament_cppcheck'
Call Stack (most recent call first):
  /work/main/.venv/share/rosidl_generator_c/cmake/rosidl_generator_c_generate_interfaces.cmake:216 (ament_cppcheck)
  /work/main/.venv/share/ament_cmake_core/cmake/core/ament_execute_extensions.cmake:48 (include)
  /work/main/.venv/share/rosidl_cmake/cmake/rosidl_generate_interfaces.cmake:280 (ament_execute_extensions)
  CMakeLists.txt:50 (rosidl_generate_interfaces)
"""

# find_package(tdep REQUIRED) in `if(BUILD_TESTING)`, tdep a package of the workspace never built
TEST_DEPENDENCY_NOT_BUILT = """\
CMake Error at CMakeLists.txt:5 (find_package):
  By not providing "Findtdep.cmake" in CMAKE_MODULE_PATH this project has
  asked CMake to find a package configuration file provided by "tdep", but
  CMake did not find one.

  Could not find a package configuration file provided by "tdep" with any of
  the following names:

    tdepConfig.cmake
    tdep-config.cmake

  Add the installation prefix of "tdep" to CMAKE_PREFIX_PATH or set
  "tdep_DIR" to a directory containing one of the above files.  If "tdep"
  provides a separate development package or SDK, be sure it has been
  installed.
"""


def package(name: str = "pkg", build: tuple[str, ...] = (), test: tuple[str, ...] = ()) -> Package:
    return Package(name, f"src/{name}", "ros.ament_cmake",
                   {"build": {"ament_cmake", *build}, "run": set(build), "test": set(test)})


def test_a_missing_ament_lint_auto_is_a_test_tool_to_install_or_build_without() -> None:
    hint = failure_hint(LINT_AUTO_MISSING, package(test=("ament_lint_auto", "ament_lint_common")), {"pkg"}, "jazzy")
    assert hint == ("the test tool ament_lint_auto is not installed: build without tests "
                    "(--cmake-args -DBUILD_TESTING=OFF), or install ros-jazzy-ament-lint-auto")


def test_a_missing_linter_program_of_an_interface_package_is_named_though_not_a_declared_dependency() -> None:
    hint = failure_hint(CPPCHECK_MISSING, package("std_msgs", test=("ament_lint_common",)), {"std_msgs"}, "jazzy")
    assert hint == ("the test tool ament_cppcheck is not installed: build without tests "
                    "(--cmake-args -DBUILD_TESTING=OFF), or install ros-jazzy-ament-cppcheck")


def test_a_test_dependency_of_the_workspace_not_built_is_to_build_too_or_to_build_without_tests() -> None:
    hint = failure_hint(TEST_DEPENDENCY_NOT_BUILT, package("user", test=("tdep",)), {"user", "tdep"}, "jazzy")
    assert hint == ("tdep is in the workspace but not built: build it too (--packages-up-to user), "
                    "or build without tests (--cmake-args -DBUILD_TESTING=OFF)")
    # a build dependency not built: turning the tests off would not help
    hint = failure_hint(TEST_DEPENDENCY_NOT_BUILT, package("user", build=("tdep",)), {"user", "tdep"}, "jazzy")
    assert hint == "tdep is in the workspace but not built: build it too (--packages-up-to user)"


def test_a_missing_package_that_is_no_test_tool_gets_no_hint() -> None:
    missing_library = TEST_DEPENDENCY_NOT_BUILT.replace("tdep", "yaml_cpp_vendor")
    assert failure_hint(missing_library, package(build=("yaml_cpp_vendor",)), {"pkg"}, "jazzy") == ""
    assert failure_hint("CMake Error at CMakeLists.txt:3 (add_executable):\n  Cannot find source file:\n",
                        package(), {"pkg"}, "jazzy") == ""


def test_a_test_only_dependency_counts_as_a_test_tool_and_without_a_distribution_the_ros_names_are_given() -> None:
    missing = TEST_DEPENDENCY_NOT_BUILT.replace("tdep", "ros_testing")
    assert failure_hint(missing, package(test=("ros_testing",)), {"pkg"}, None) == (
        "the test tool ros_testing is not installed: build without tests (--cmake-args -DBUILD_TESTING=OFF), "
        "or install ros_testing")


@pytest.mark.slow
def test_the_console_line_of_a_package_that_needs_ament_lint_auto_says_how_to_go_on(tmp_path: Path) -> None:
    workspace = tmp_path / "ws"
    add_cmake_package(workspace, "linted", "cmake_minimum_required(VERSION 3.8)\nproject(linted NONE)\n"
                      "find_package(ament_cmake REQUIRED)\nif(BUILD_TESTING)\n  find_package(ament_lint_auto REQUIRED)\n"
                      "  ament_lint_auto_find_test_dependencies()\nendif()\nament_package()\n",
                      depends=("ament_cmake",), test_depends=("ament_lint_auto",), build_type="ament_cmake")
    failed = roc("work", "build", cwd=workspace)
    assert failed.returncode == 1
    line = next(line for line in failed.stdout.splitlines() if line.startswith("Failed   <<< linted"))
    assert line.endswith(", CMake configure failed]: the test tool ament_lint_auto is not installed: build without "
                         f"tests (--cmake-args -DBUILD_TESTING=OFF), or install ros-{DISTRO}-ament-lint-auto"), line
    built = roc("work", "build", "--cmake-args", "-DBUILD_TESTING=OFF", cwd=workspace)
    assert built.returncode == 0, built.stdout + built.stderr


def add_python_package(workspace: Path, name: str, test_depends: tuple[str, ...]) -> None:
    directory = workspace / "src" / name
    (directory / name).mkdir(parents=True)
    (directory / name / "__init__.py").write_text("")
    (directory / "resource").mkdir()
    (directory / "resource" / name).write_text("")
    (directory / "package.xml").write_text(
        f'<?xml version="1.0"?><package format="3"><name>{name}</name><version>0.0.1</version>'
        f'<description>test</description><maintainer email="roc@example.com">roc</maintainer>'
        f"<license>Apache-2.0</license>{''.join(f'<test_depend>{d}</test_depend>' for d in test_depends)}"
        f"<export><build_type>ament_python</build_type></export></package>")
    (directory / "setup.py").write_text(
        f"from setuptools import setup\nsetup(name='{name}', version='0.0.1', packages=['{name}'], data_files=["
        f"('share/ament_index/resource_index/packages', ['resource/{name}']), ('share/{name}', ['package.xml'])])\n")


@pytest.mark.slow
@pytest.mark.colcon
def test_packages_select_builds_a_package_whose_test_dependency_is_not_built_where_colcon_refuses(
        tmp_path: Path) -> None:
    workspace = tmp_path / "ws"
    add_cmake_package(workspace, "tdep", "cmake_minimum_required(VERSION 3.8)\nproject(tdep NONE)\n"
                      "find_package(ament_cmake REQUIRED)\nament_package()\n",
                      depends=("ament_cmake",), build_type="ament_cmake")
    add_python_package(workspace, "userpy", test_depends=("tdep",))
    add_cmake_package(workspace, "user", "cmake_minimum_required(VERSION 3.8)\nproject(user NONE)\n"
                      "find_package(ament_cmake REQUIRED)\nif(BUILD_TESTING)\n  find_package(tdep REQUIRED)\nendif()\n"
                      "ament_package()\n", depends=("ament_cmake",), test_depends=("tdep",), build_type="ament_cmake")
    colcon_copy = tmp_path / "colcon"
    shutil.copytree(workspace, colcon_copy)

    refused = colcon("build", "--packages-select", "userpy", cwd=colcon_copy)
    assert "Check that the following packages have been built:\n- tdep" in refused.stderr, refused.stderr
    assert not (colcon_copy / "install" / "userpy" / "share" / "userpy" / "package.xml").exists()

    built = roc("work", "build", "--packages-select", "userpy", cwd=workspace)  # its build does not need tdep
    assert built.returncode == 0, built.stdout + built.stderr
    assert (workspace / "install" / "userpy" / "share" / "userpy" / "package.xml").is_file()

    # a CMakeLists that finds its test dependency while BUILD_TESTING is on cannot configure without it
    failed = roc("work", "build", "--packages-select", "user", cwd=workspace)
    assert failed.returncode == 1
    assert "CMake configure failed]: tdep is in the workspace but not built: build it too (--packages-up-to user), or " \
           "build without tests (--cmake-args -DBUILD_TESTING=OFF)" in failed.stdout, failed.stdout
    without_tests = roc("work", "build", "--packages-select", "user", "--cmake-args", "-DBUILD_TESTING=OFF",
                        cwd=workspace)
    assert without_tests.returncode == 0, without_tests.stdout + without_tests.stderr
    up_to = roc("work", "build", "--packages-up-to", "user", cwd=workspace)
    assert up_to.returncode == 0, up_to.stdout + up_to.stderr
