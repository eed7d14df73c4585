"""The order of a first build, before any duration is recorded: the package with more to compile starts
first (roc.builder.estimate), not the first by name."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from helpers.build import add_plain_package, roc

from roc.builder.estimate import AT_LEAST, SECONDS_EACH, estimated_seconds, package_weight
from roc.builder.state import STATE_FILE


def test_compiled_sources_and_interface_definitions_count_and_hidden_folders_do_not(tmp_path: Path) -> None:
    for name in ("src/a.cpp", "src/b.c", "msg/M.msg", "srv/S.srv", "README.md", "CMakeLists.txt", ".git/x.cpp"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text("")
    assert estimated_seconds(tmp_path) == 4 * SECONDS_EACH


def test_a_package_with_nothing_to_compile_weighs_as_an_unknown_task(tmp_path: Path) -> None:
    (tmp_path / "setup.py").write_text("")
    assert estimated_seconds(tmp_path) == AT_LEAST


def test_a_recorded_duration_wins_and_a_package_restored_without_one_is_not_walked(tmp_path: Path) -> None:
    source, build_dir = tmp_path / "src", tmp_path / "build"
    source.mkdir()
    (source / "a.cpp").write_text("")
    assert package_weight(None, source, build_dir) == SECONDS_EACH
    assert package_weight(7.5, source, build_dir) == 7.5
    build_dir.mkdir()
    (build_dir / STATE_FILE).write_text("{}")  # built elsewhere and restored: no duration recorded here
    assert package_weight(None, source, build_dir) == AT_LEAST


@pytest.mark.slow
def test_a_first_build_starts_the_package_with_more_to_compile_first(tmp_path: Path) -> None:
    add_plain_package(tmp_path, "a_small")
    add_plain_package(tmp_path, "b_large")
    for index in range(3):
        (tmp_path / "src" / "b_large" / f"part{index}.cpp").write_text("")
    built = roc("work", "build", "--parallel-workers", "1", cwd=tmp_path)
    assert built.returncode == 0, built.stdout + built.stderr
    events = [json.loads(line) for line in (tmp_path / "log" / "latest_build" / "events.log").read_text().splitlines()]
    assert [e["task"] for e in events if e["event"] == "TaskStarted"] == ["b_large", "a_small"]
