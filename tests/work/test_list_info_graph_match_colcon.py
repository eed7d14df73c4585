"""``roc work list|info|graph`` against the real colcon (the test oracle) on the same workspaces, in the
same environment: the fixture workspaces under ``workspaces/fixtures/`` and a workspace made of the real
ROS 2 manifests installed in this environment.

colcon's start-up is slow, so each test runs all its colcon commands in one interpreter
(``run_colcon_batch``) and roc in this process; a test reports every command whose output differs.
Tests of behaviour where roc deliberately differs from colcon say so.
"""

from __future__ import annotations

import difflib
import shutil
import sys
from pathlib import Path

import pytest
from helpers.build import copy_fixture
from helpers.fixture_workspaces import (
    GOOD_FIXTURES,
    colcon_available,
    normalize,
    run_colcon_batch,
    run_roc_inprocess,
    tool_environment,
)

pytestmark = [
    pytest.mark.colcon,
    pytest.mark.slow,  # runs the real colcon
    pytest.mark.skipif(not colcon_available(), reason="the real colcon (the test oracle) is not installed"),
]

OUTPUTS = (["list"], ["list", "-t"], ["list", "-n"], ["list", "-p"], ["graph"], ["graph", "--dot"], ["info"])

# Package selection, compared with `list -t` on the 'selection' fixture, whose graph is:
# util -build-> core, extra; lib_a -depend-> core, msgs; lib_b -exec-> util, -test-> test_helper;
# test_helper -exec-> core; app -depend-> lib_a, -build-> lib_b; tool -exec-> msgs, -test-> app; standalone.
SELECTION_OPTIONS = (
    ["--packages-up-to", "app"],
    ["--packages-up-to", "lib_b", "tool"],
    ["--packages-up-to-regex", "lib_."],
    ["--packages-up-to", "app", "--packages-up-to-regex", "test.*"],
    ["--packages-above", "core"],
    ["--packages-above", "extra"],
    ["--packages-above-and-dependencies", "util"],
    ["--packages-above-depth", "0", "core"],
    ["--packages-above-depth", "1", "core"],
    ["--packages-above-depth", "2", "util", "msgs"],
    ["--packages-select-by-dep", "util"],
    ["--packages-skip-by-dep", "msgs"],
    ["--packages-skip-up-to", "lib_b"],
    ["--packages-select", "app", "core"],
    ["--packages-skip", "app", "core"],
    ["--packages-select-regex", "lib_.*"],
    ["--packages-skip-regex", "lib", ".*_helper"],
    ["--packages-ignore", "lib_b"],
    ["--packages-ignore-regex", ".*a.*"],
    ["--packages-ignore", "util", "--packages-up-to", "app"],
    ["--packages-start", "lib_a"],
    ["--packages-end", "util"],
    ["--packages-start", "lib_a", "--packages-end", "lib_b"],
    ["--packages-select", "app", "--packages-up-to", "lib_a"],
    ["--packages-select"],
    ["--paths", "src/*"],
    ["--paths", "src/app", "src/core"],
    ["--paths", "src/app", "--base-paths", "src"],
    ["--base-paths", "src"],
)
GRAPH_OPTIONS = (
    ["graph", "--density", "--legend"],
    ["graph", "--packages-up-to", "lib_b", "--density"],
    ["graph", "--dot", "--legend"],
    ["graph", "--dot", "--dot-cluster"],
    ["graph", "--dot", "--packages-select", "app", "util"],
    ["graph", "--dot", "--packages-select", "app", "util", "--dot-include-skipped"],
    ["graph", "--dot", "--packages-skip", "lib_a", "lib_b"],
    ["graph", "--dot", "--packages-up-to", "lib_b", "--dot-include-skipped", "--dot-cluster"],
    ["info", "app", "core"],
    ["info", "--packages-above", "util"],
    ["list", "-p", "--packages-up-to", "tool"],
)
# colcon runs every setup.py of the python fixture: there only the outputs that show identification.
PYTHON_OUTPUTS = (["list", "-t"], ["info"], ["graph", "--dot"])
CASES = {
    **{name: (name, list(PYTHON_OUTPUTS if name == "python" else OUTPUTS)) for name in GOOD_FIXTURES},
    "selection-options": ("selection", [["list", "-t", *options] for options in SELECTION_OPTIONS]),
    "selection-graph": ("selection", list(GRAPH_OPTIONS)),
}
CASES["discovery"][1].append(["graph", "--dot", "--dot-cluster"])
CASES["formats"][1].append(["list", "-t", "--packages-select-by-dep", "member_a"])

# What each fixture must hold, so that a fixture that both tools misread the same way still fails.
EXPECTED_NAMES = {
    "discovery": ["deep_pkg", "mid_pkg", "top_pkg"],
    "formats": ["base_msgs", "fmt1_pkg", "fmt2_pkg", "fmt3_pkg", "member_a", "member_b", "member_ros1", "tools"],
    "cmake": ["noname", "plain_app", "plain_lib", "plain_util"],
    "python": ["ament_py", "py_cfg", "py_const", "py_dynamic", "py_literal"],
    "colcon_pkg": ["cmake_typed", "py_typed", "renamed", "ros_hooks", "typed_only"],
    "selection": ["app", "core", "extra", "lib_a", "lib_b", "msgs", "standalone", "test_helper", "tool", "util"],
}


def differences(commands: list[list[str]], workspace: Path, env: dict[str, str]) -> list[str]:
    """A report for each command whose exit code or normalized stdout differs between colcon and roc."""
    reports = []
    for command, expected in zip(commands, run_colcon_batch(commands, workspace, env)):
        actual = run_roc_inprocess(["work", *command], workspace, env)
        want, got = normalize(command, expected.stdout), normalize(command, actual.stdout)
        if actual.returncode != expected.returncode or want != got:
            diff = "\n".join(difflib.unified_diff(want, got, "colcon", "roc", lineterm=""))
            reports.append(f"$ {' '.join(command)}: colcon exit {expected.returncode}, roc exit "
                           f"{actual.returncode}\n{diff}\n{actual.stderr}")
    return reports


@pytest.mark.parametrize("case", sorted(CASES))
def test_roc_matches_colcon(case: str, tmp_path: Path) -> None:
    fixture, commands = CASES[case]
    workspace = copy_fixture(fixture, tmp_path / fixture)
    reports = differences(commands, workspace, tool_environment())
    assert not reports, "\n\n".join(reports)


@pytest.mark.parametrize("fixture", GOOD_FIXTURES)
def test_fixture_holds_the_expected_packages(fixture: str, tmp_path: Path) -> None:
    workspace = copy_fixture(fixture, tmp_path / fixture)
    result = run_roc_inprocess(["work", "list", "-n"], workspace, tool_environment())
    assert (result.returncode, result.stdout.split(), result.stderr) == (0, EXPECTED_NAMES[fixture], "")


# --- real ROS 2 manifests ---------------------------------------------------------------------------


def real_manifests() -> list[Path]:
    return sorted(Path(sys.prefix, "share").glob("*/package.xml"))


@pytest.mark.skipif(len(real_manifests()) < 20, reason="the ROS 2 packages are not installed in this environment")
def test_real_ros_manifests_match_colcon(tmp_path: Path) -> None:
    """One directory per installed ROS 2 package with a copy of its package.xml (and an empty setup.py
    for ament_python ones, which colcon needs to identify them): roc has never seen these manifests."""
    source = tmp_path / "ws" / "src"
    for manifest in real_manifests():
        package = source / manifest.parent.name
        package.mkdir(parents=True)
        shutil.copy(manifest, package / "package.xml")
        if "<build_type>ament_python</build_type>" in manifest.read_text():
            (package / "setup.py").write_text("")
    commands = [
        ["list", "-t"], ["info"], ["graph"], ["graph", "--dot"],
        ["list", "-t", "--packages-up-to", "rclpy"],
        ["list", "-t", "--packages-above", "rcutils"],
        ["graph", "--dot", "--packages-select-by-dep", "rosidl_default_runtime"],
    ]
    reports = differences(commands, source.parent, tool_environment())
    assert not reports, "\n\n".join(reports)
    listed = run_roc_inprocess(["work", "list", "-n"], source.parent, tool_environment()).stdout.split()
    assert len(listed) == len(real_manifests())


# --- deliberate differences ----------------------------------------------------------------------


def test_ros_version_defaults_to_2(tmp_path: Path) -> None:
    # Deliberate difference: with ROS_VERSION and ROS_PYTHON_VERSION unset, roc evaluates conditions
    # as if they were 2 and 3 (a venv with the ROS wheels sets neither); colcon sees empty strings.
    workspace = copy_fixture("formats", tmp_path / "formats")
    [colcon_set] = run_colcon_batch([["info", "fmt3_pkg"]], workspace, tool_environment())
    roc_unset = run_roc_inprocess(["work", "info", "fmt3_pkg"], workspace,
                                  tool_environment(ROS_VERSION=None, ROS_PYTHON_VERSION=None))
    assert normalize(["info"], roc_unset.stdout) == normalize(["info"], colcon_set.stdout)
    assert "ament_cmake" in roc_unset.stdout and "py3_dep" in roc_unset.stdout
    roc_ros1 = run_roc_inprocess(["work", "info", "fmt3_pkg"], workspace, tool_environment(ROS_VERSION="1"))
    assert "type: ros.catkin" in roc_ros1.stdout and "catkin" in roc_ros1.stdout.split("build:")[1]


def test_unknown_package_name_is_a_usage_error(tmp_path: Path) -> None:
    # Deliberate difference: colcon exits 1 ("Package 'x' ... was not found"); roc exits 2, as for any
    # usage error, and suggests the close names.
    workspace = copy_fixture("selection", tmp_path / "selection")
    commands = [["list", "--packages-up-to", "ap"], ["info", "ap"]]
    for command, expected in zip(commands, run_colcon_batch(commands, workspace, tool_environment())):
        actual = run_roc_inprocess(["work", *command], workspace, tool_environment())
        assert expected.returncode == 1
        assert actual.returncode == 2 and "did you mean app?" in actual.stderr


def test_duplicate_names_are_an_error(tmp_path: Path) -> None:
    # Deliberate difference: colcon lists both packages (and fails later, in build); roc refuses in
    # every verb and names both paths.
    workspace = copy_fixture("bad_duplicate_names", tmp_path / "bad_duplicate_names")
    [expected] = run_colcon_batch([["list", "-n"]], workspace, tool_environment())
    assert expected.stdout.split().count("same_name") == 2
    actual = run_roc_inprocess(["work", "list", "-n"], workspace, tool_environment())
    assert actual.returncode == 1 and actual.stdout == ""
    assert "src/first/same_name" in actual.stderr and "src/second/same_name" in actual.stderr


def test_cycle_message_shows_the_cycle(tmp_path: Path) -> None:
    # Deliberate difference: colcon prints every package still unordered with its remaining
    # dependencies; roc prints the cycle itself, with the dependency categories on each edge.
    workspace = copy_fixture("bad_cycle", tmp_path / "bad_cycle")
    [expected] = run_colcon_batch([["list", "-t"]], workspace, tool_environment())
    actual = run_roc_inprocess(["work", "list", "-t"], workspace, tool_environment())
    assert expected.returncode == actual.returncode == 1
    assert "cyc_a -[build,run]-> cyc_b -[build]-> cyc_c -[run]-> cyc_a" in actual.stderr


def test_broken_manifest_is_an_error_not_a_skip(tmp_path: Path) -> None:
    # Deliberate difference: colcon drops a package whose package.xml does not parse (with a warning
    # only when it references the ROS schema) and goes on without it; roc stops and names the line.
    workspace = copy_fixture("bad_malformed_xml", tmp_path / "bad_malformed_xml")
    [expected] = run_colcon_batch([["list", "-n"]], workspace, tool_environment())
    assert (expected.returncode, expected.stdout.split()) == (0, ["good"])
    actual = run_roc_inprocess(["work", "list", "-n"], workspace, tool_environment())
    assert actual.returncode == 1 and "broken/package.xml:8: malformed XML" in actual.stderr


def test_manifest_that_catkin_pkg_rejects_is_kept(tmp_path: Path) -> None:
    # Deliberate difference: catkin_pkg's validation (here: a maintainer without email) makes colcon
    # silently drop the package; roc reads what it needs (name, version, dependencies) and keeps it.
    workspace = copy_fixture("formats", tmp_path / "formats")
    manifest = workspace / "src" / "base_msgs" / "package.xml"
    manifest.write_text(manifest.read_text().replace(' email="anon@example.com"', ""))
    [expected] = run_colcon_batch([["list", "-n"]], workspace, tool_environment())
    actual = run_roc_inprocess(["work", "list", "-n"], workspace, tool_environment())
    assert "base_msgs" not in expected.stdout.split()
    assert "base_msgs" in actual.stdout.split()


def test_ament_python_without_setup_py_is_left_out(tmp_path: Path) -> None:
    # Deliberate difference: colcon lists an ament_python package that has no setup.py (its build then
    # fails); roc leaves it out with a warning that says what is missing.
    workspace = tmp_path / "ws"
    shutil.copytree(copy_fixture("python", tmp_path / "python") / "src" / "ament_py", workspace / "src" / "ament_py")
    (workspace / "src" / "ament_py" / "setup.py").unlink()
    [expected] = run_colcon_batch([["list", "-n"]], workspace, tool_environment())
    actual = run_roc_inprocess(["work", "list", "-n"], workspace, tool_environment())
    assert "ament_py" in expected.stdout.split()
    assert "ament_py" not in actual.stdout.split() and actual.returncode == 0
    assert "ament_python but no setup.py" in actual.stderr

