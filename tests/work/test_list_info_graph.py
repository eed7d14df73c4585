"""roc work list, info and graph with --format json (their text output is compared with colcon's in
test_list_info_graph_match_colcon.py)."""

from __future__ import annotations

import json
from pathlib import Path

from helpers.build import copy_fixture
from helpers.fixture_workspaces import (
    run_roc_inprocess,
    tool_environment,
)


def roc_json(workspace: Path, *argv: str):
    result = run_roc_inprocess(["work", *argv, "--format", "json"], workspace, tool_environment())
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


def test_list_json(tmp_path: Path) -> None:
    workspace = copy_fixture("cmake", tmp_path / "cmake")
    assert roc_json(workspace, "list", "-t") == [
        {"name": "plain_lib", "path": "src/plain_lib", "type": "cmake"},
        {"name": "plain_util", "path": "src/util_dir", "type": "cmake"},
        {"name": "plain_app", "path": "src/plain_app", "type": "cmake"},
        {"name": "noname", "path": "src/noname", "type": "cmake"},
    ]
    assert [p["name"] for p in roc_json(workspace, "list")] == ["noname", "plain_app", "plain_lib", "plain_util"]


def test_info_json(tmp_path: Path) -> None:
    workspace = copy_fixture("formats", tmp_path / "formats")
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
    [plain] = roc_json(copy_fixture("colcon_pkg", tmp_path / "colcon_pkg"), "info", "renamed")
    assert plain["hooks"] == ["share/renamed/hook/extra.dsv", "share/renamed/hook/extra.sh"]
    assert "manifest" not in plain


def test_graph_json(tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path / "selection")
    graph = roc_json(workspace, "graph", "--packages-select", "app", "lib_b", "core")
    assert graph["nodes"] == [
        {"name": n, "path": f"src/{n}", "type": "ros.ament_cmake"} for n in ("core", "lib_b", "app")
    ]
    edges = {(e["from"], e["to"]): (e["categories"], e["indirect"]) for e in graph["edges"]}
    # app -> lib_b is direct (build); lib_b reaches core only through packages not shown (util, test_helper)
    assert edges == {("app", "lib_b"): (["build"], False), ("app", "core"): (["build", "run"], True),
                     ("lib_b", "core"): (["run", "test"], True)}
