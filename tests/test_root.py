"""Workspace-root search, and the command line around it: version, help, usage errors, ``-C``, the
workspace-root note, ``--format json`` and shell completion."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from fixture_workspaces import (
    copy_fixture,
    run_roc,
    run_roc_inprocess,
    tool_environment,
)

from roc import __version__
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
    workspace = copy_fixture("selection", tmp_path)
    result = run_roc_inprocess(["work", "list", "-n"], workspace / "src" / "app", tool_environment())
    assert result.returncode == 0 and "app" in result.stdout.split()
    assert result.stderr == f"roc: using workspace root {workspace}\n"
    at_root = run_roc_inprocess(["work", "list", "-n"], workspace, tool_environment())
    assert at_root.stdout == result.stdout and at_root.stderr == ""


def test_paths_are_relative_to_the_root_from_a_subdirectory(tmp_path: Path) -> None:
    workspace = copy_fixture("discovery", tmp_path)
    result = run_roc_inprocess(["work", "list", "-p"], workspace / "src" / "group", tool_environment())
    assert result.stdout.split() == ["src/group/mid_pkg", "src/group/sub/deeper/deep_pkg", "src/top_pkg"]


def test_explicit_base_paths_are_taken_from_the_current_directory(tmp_path: Path) -> None:
    workspace = copy_fixture("discovery", tmp_path)
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


def test_dash_c_runs_in_another_directory(tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path)
    result = run_roc("-C", str(workspace), "work", "list", "-t", "-n", "--packages-up-to", "lib_a", cwd=tmp_path)
    assert (result.returncode, result.stdout.split(), result.stderr) == (0, ["core", "msgs", "lib_a"], "")
    missing = run_roc("-C", str(tmp_path / "missing"), "work", "list", cwd=tmp_path)
    assert missing.returncode == 1
    assert missing.stderr == f"roc: error: -C {tmp_path / 'missing'}: No such file or directory\n"


def test_version(tmp_path: Path) -> None:
    result = run_roc("--version", cwd=tmp_path)
    assert (result.returncode, result.stdout) == (0, f"roc {__version__}\n")


def test_help(tmp_path: Path) -> None:
    result = run_roc("--help", cwd=tmp_path)
    assert result.returncode == 0
    assert result.stdout.startswith("usage: roc ") and "work" in result.stdout and "completion" in result.stdout
    listing = run_roc("work", "list", "--help", cwd=tmp_path)
    assert listing.returncode == 0 and "--packages-up-to" in listing.stdout and "--topological-order" in listing.stdout


@pytest.mark.parametrize("argv, message", [
    (["nosuchcommand"], "roc: error: unknown command 'nosuchcommand'; choose from work, w, topic"),
    (["work", "list", "--bogus"], "roc work list: error: unrecognized arguments: --bogus"),
    (["work", "list", "-n", "-p"], "not allowed with argument"),
    (["work", "graph", "--format", "yaml"], "invalid choice: 'yaml'"),
    (["completion", "tcsh"], "invalid choice: 'tcsh'"),
])
def test_bad_arguments_are_one_line_and_exit_2(tmp_path: Path, argv: list[str], message: str) -> None:
    result = run_roc(*argv, cwd=tmp_path)
    assert result.returncode == 2
    assert len(result.stderr.splitlines()) == 1 and message in result.stderr
    assert "--help" in result.stderr  # says where to look


def test_group_without_command_prints_its_help(tmp_path: Path) -> None:
    result = run_roc("work", cwd=tmp_path)
    assert result.returncode == 2 and result.stderr.startswith("usage: roc work") and result.stdout == ""


# --- --format json -----------------------------------------------------------------------------


def roc_json(workspace: Path, *argv: str):
    result = run_roc_inprocess(["work", *argv, "--format", "json"], workspace, tool_environment())
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


def test_list_json(tmp_path: Path) -> None:
    workspace = copy_fixture("cmake", tmp_path)
    assert roc_json(workspace, "list", "-t") == [
        {"name": "plain_lib", "path": "src/plain_lib", "type": "cmake"},
        {"name": "plain_util", "path": "src/util_dir", "type": "cmake"},
        {"name": "plain_app", "path": "src/plain_app", "type": "cmake"},
        {"name": "noname", "path": "src/noname", "type": "cmake"},
    ]
    assert [p["name"] for p in roc_json(workspace, "list")] == ["noname", "plain_app", "plain_lib", "plain_util"]


def test_info_json(tmp_path: Path) -> None:
    workspace = copy_fixture("formats", tmp_path)
    [info] = roc_json(workspace, "info", "fmt3_pkg")
    assert set(info) == {"name", "path", "type", "dependencies", "version_constraints", "hooks", "metadata", "manifest"}
    assert (info["name"], info["path"], info["type"]) == ("fmt3_pkg", "src/fmt3_pkg", "ros.ament_cmake")
    assert info["dependencies"]["build"] == ["ament_cmake", "fmt2_pkg", "member_a", "member_b"]
    assert info["version_constraints"] == {"fmt2_pkg": {"version_gte": "2.0.0", "version_lt": "3.0.0"}}
    assert info["metadata"] == {"version": "3.0.0", "maintainers": ["Three <three@example.com>"]}
    manifest = info["manifest"]
    assert (manifest["format"], manifest["build_type"], manifest["group_depends"]) == (3, "ament_cmake", ["fmt_group"])
    assert {"name": "jazzy_only", "tag": "exec_depend", "condition": "$ROS_DISTRO == jazzy"} in manifest["dependencies"]
    assert "not_jazzy" not in [d["name"] for d in manifest["dependencies"]]
    [plain] = roc_json(copy_fixture("colcon_pkg", tmp_path), "info", "renamed")
    assert plain["hooks"] == ["share/renamed/hook/extra.dsv", "share/renamed/hook/extra.sh"]
    assert "manifest" not in plain


def test_graph_json(tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path)
    graph = roc_json(workspace, "graph", "--packages-select", "app", "lib_b", "core")
    assert graph["nodes"] == [
        {"name": n, "path": f"src/{n}", "type": "ros.ament_cmake"} for n in ("core", "lib_b", "app")
    ]
    edges = {(e["from"], e["to"]): (e["categories"], e["indirect"]) for e in graph["edges"]}
    # app -> lib_b is direct (build); lib_b reaches core only through packages not shown (util, test_helper)
    assert edges == {("app", "lib_b"): (["build"], False), ("app", "core"): (["build", "run"], True),
                     ("lib_b", "core"): (["run", "test"], True)}


# --- completion --------------------------------------------------------------------------------


def completion_script(shell: str, tmp_path: Path) -> Path:
    result = run_roc("completion", shell, cwd=tmp_path)
    assert result.returncode == 0 and result.stderr == ""
    path = tmp_path / f"roc.{shell}"
    path.write_text(result.stdout)
    return path


def test_bash_completion_parses_and_completes(tmp_path: Path) -> None:
    script = completion_script("bash", tmp_path)
    assert subprocess.run(["bash", "-n", str(script)], capture_output=True).returncode == 0
    workspace = copy_fixture("selection", tmp_path)
    # roc must be on PATH for package names: the directory of this interpreter holds the roc script
    env = {**tool_environment(), "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    probe = (f"source {script}\n"
             "COMP_WORDS=(roc w li); COMP_CWORD=2; _roc_complete; echo \"${COMPREPLY[*]}\"\n"
             "COMP_WORDS=(roc work list --packages-up); COMP_CWORD=3; _roc_complete; echo \"${COMPREPLY[*]}\"\n"
             "COMP_WORDS=(roc work list --packages-up-to li); COMP_CWORD=4; _roc_complete; echo \"${COMPREPLY[*]}\"\n")
    result = subprocess.run(["bash", "-c", probe], cwd=workspace, env=env, capture_output=True, text=True, timeout=60)
    expected = ["list", "--packages-up-to --packages-up-to-regex", "lib_a lib_b"]
    assert result.stdout.splitlines() == expected, result.stderr


@pytest.mark.parametrize("shell", ["zsh", "fish"])
def test_other_shells_parse(shell: str, tmp_path: Path) -> None:
    script = completion_script(shell, tmp_path)
    assert script.read_text().startswith(f"# roc {shell} completion")
    if shutil.which(shell) is None:
        pytest.skip(f"{shell} is not installed")
    result = subprocess.run([shell, "-n", str(script)], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
