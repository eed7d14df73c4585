"""Workspace-root search: which directory is the root, the note when roc runs from a subdirectory,
and which paths are taken relative to what."""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers.build import copy_fixture
from helpers.fixture_workspaces import (
    run_roc_inprocess,
    tool_environment,
)

from roc.workspace.root import find_workspace_root, is_workspace_root


def make_package(directory: Path, name: str) -> Path:
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "package.xml").write_text(
        f'<package format="3"><name>{name}</name><version>1.0.0</version><description>d</description>'
        '<maintainer email="m@example.com">M</maintainer><license>MIT</license>'
        "<export><build_type>ament_cmake</build_type></export></package>\n"
    )
    return directory


@pytest.fixture
def ws(tmp_path: Path) -> Path:
    """tmp/ws/src/pkg/{src,include/pkg}: a package with its own src/ directory."""
    root = tmp_path / "ws"
    package = make_package(root / "src" / "pkg", "pkg")
    (package / "src").mkdir()
    (package / "include" / "pkg").mkdir(parents=True)
    return root


def outside_any_workspace(path: Path) -> bool:
    return find_workspace_root(path.parent) is None


# --- root search -------------------------------------------------------------------------------


@pytest.mark.parametrize("start", [".", "src", "src/pkg", "src/pkg/include/pkg"])
def test_root_is_found_from_inside(ws: Path, start: str) -> None:
    assert find_workspace_root(ws / start) == ws


def test_package_with_its_own_src_is_not_a_root(ws: Path) -> None:
    assert (ws / "src" / "pkg" / "src").is_dir()
    assert not is_workspace_root(ws / "src" / "pkg")
    assert find_workspace_root(ws / "src" / "pkg" / "src") == ws


@pytest.mark.parametrize("marker", ["package.xml", "CMakeLists.txt", "setup.py", "colcon.pkg"])
def test_any_package_file_rules_a_directory_out(tmp_path: Path, marker: str) -> None:
    (tmp_path / "src").mkdir()
    (tmp_path / marker).write_text("")
    assert not is_workspace_root(tmp_path)


@pytest.mark.parametrize("marker", ["roc.toml", "build/.built_by", "install/.colcon_install_layout",
                                    "build/COLCON_IGNORE", "install/COLCON_IGNORE", "log/COLCON_IGNORE"])
def test_roc_toml_and_colcon_bases_mark_a_root_without_src(tmp_path: Path, marker: str) -> None:
    root = tmp_path / "ws"
    (root / marker).parent.mkdir(parents=True, exist_ok=True)
    (root / marker).write_text("")
    (root / "pkg").mkdir()
    assert find_workspace_root(root / "pkg") == root


def test_a_bare_build_directory_is_no_marker(tmp_path: Path) -> None:
    root = tmp_path / "ws"
    (root / "build").mkdir(parents=True)  # e.g. a CMake build directory, not made by colcon or roc
    if not outside_any_workspace(root):
        pytest.skip("an ancestor of the temporary directory looks like a workspace")
    assert find_workspace_root(root) is None


def test_nearest_root_wins(ws: Path) -> None:
    inner = ws / "src" / "nested_ws"
    (inner / "src").mkdir(parents=True)
    assert find_workspace_root(inner / "src") == inner


# --- the command line ------------------------------------------------------------------------


def test_note_when_run_from_a_subdirectory(tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path / "selection")
    result = run_roc_inprocess(["work", "list", "-n"], workspace / "src" / "app", tool_environment())
    assert result.returncode == 0 and "app" in result.stdout.split()
    assert result.stderr == f"roc: using workspace root {workspace}\n"
    at_root = run_roc_inprocess(["work", "list", "-n"], workspace, tool_environment())
    assert at_root.stdout == result.stdout and at_root.stderr == ""


def test_paths_are_relative_to_the_root_from_a_subdirectory(tmp_path: Path) -> None:
    workspace = copy_fixture("discovery", tmp_path / "discovery")
    result = run_roc_inprocess(["work", "list", "-p"], workspace / "src" / "group", tool_environment())
    assert result.stdout.split() == ["src/group/mid_pkg", "src/group/sub/deeper/deep_pkg", "src/top_pkg"]


def test_explicit_base_paths_are_taken_from_the_current_directory(tmp_path: Path) -> None:
    workspace = copy_fixture("discovery", tmp_path / "discovery")
    result = run_roc_inprocess(["work", "list", "-n", "--base-paths", "."], workspace / "src" / "group",
                               tool_environment())
    assert (result.stdout.split(), result.stderr) == (["deep_pkg", "mid_pkg"], "")


def test_fallback_is_the_current_directory(tmp_path: Path) -> None:
    loose = tmp_path / "loose"
    make_package(loose / "one", "one")
    if not outside_any_workspace(loose):
        pytest.skip("an ancestor of the temporary directory looks like a workspace")
    result = run_roc_inprocess(["work", "list"], loose, tool_environment())
    assert (result.stdout, result.stderr) == ("one\tone\t(ros.ament_cmake)\n", "")


# --- --format json -----------------------------------------------------------------------------


# --- completion --------------------------------------------------------------------------------
