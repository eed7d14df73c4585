"""Fast unit tests of up-to-date checks: source stamps, reasons, build tools."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from roc.builder.fingerprint import build_tools, changes, source_parts, source_stamps
from roc.builder.state import write_state
from roc.builder.uptodate import PackageState, forced_reasons, stale_reasons
from roc.buildtypes.context import BuildOptions
from roc.workspace.package import Package


def test_source_stamps_skip_editor_droppings_hidden_dirs_and_pyc(tmp_path: Path) -> None:
    for name in ("main.c", "sub/util.h", ".x.swp", "sub/.util.h.swo", "foo~", ".#foo", "#foo#", ".DS_Store",
                 "4913", ".git/HEAD", "__pycache__/m.cpython-312.pyc", "m.pyc", "swp.c", "4913.c"):
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(name)
    stamps = source_stamps(tmp_path, {})
    assert sorted(stamps) == ["4913.c", "main.c", "sub/util.h", "swp.c"]
    size, _, digest, executable = stamps["main.c"]
    assert size == 6 and len(digest) == 64 and executable is False


def test_source_stamps_reuse_the_hash_when_size_and_mtime_match(tmp_path: Path) -> None:
    (tmp_path / "a.c").write_text("int a;")
    first = source_stamps(tmp_path, {})
    previous = {"a.c": [*first["a.c"][:2], "remembered", False]}
    assert source_stamps(tmp_path, previous)["a.c"][2] == "remembered"
    os.chmod(tmp_path / "a.c", 0o755)
    now = source_stamps(tmp_path, {})
    assert source_parts(now)["a.c"] == f"{first['a.c'][2]}:1"


def test_source_stamps_stop_at_a_nested_ignore_marker(tmp_path: Path) -> None:
    (tmp_path / "COLCON_IGNORE").write_text("")  # the package's own directory is still read
    (tmp_path / "a.c").write_text("")
    (tmp_path / "vendor").mkdir()
    (tmp_path / "vendor" / "COLCON_IGNORE").write_text("")
    (tmp_path / "vendor" / "b.c").write_text("")
    assert sorted(source_stamps(tmp_path, {})) == ["COLCON_IGNORE", "a.c"]


def test_changes_name_added_removed_changed_files_and_parts() -> None:
    before = {"sources": {"a.c": "1:0", "b.c": "2:0", "gone.h": "3:0"},
              "toolchain": {"tool ninja": "/usr/bin/ninja:1:1", "variable CC": None},
              "options": {"cmake-args": []}, "dependencies": {"dep": "f1"}}
    now = {"sources": {"a.c": "1:0", "b.c": "9:0", "new.h": "4:0"},
           "toolchain": {"tool ninja": "/tmp/ninja:5:5", "variable CC": "clang"},
           "options": {"cmake-args": ["-DX=1"]}, "dependencies": {"dep": "f2"}}
    assert changes(before, now) == [
        "files added: new.h", "files changed: b.c", "files removed: gone.h",
        "option changed: cmake-args", "toolchain changed: tool ninja, variable CC",
        "dependency changed: dep"]
    assert changes(now, now) == []


def test_changes_shorten_long_lists() -> None:
    now = {"sources": {f"f{i}.c": "x" for i in range(5)}}
    assert changes({}, now) == ["files added: f0.c, f1.c, f2.c and 2 more"]


@pytest.mark.parametrize(("build_type", "env", "args", "tools"), [
    ("cmake", {}, (), ("cmake", "make", "cc", "c++")),
    ("ament_cmake", {"CMAKE_GENERATOR": "Ninja"}, (), ("cmake", "ninja", "cc", "c++")),
    ("cmake", {"CMAKE_GENERATOR": "Ninja"}, ("-G", "Unix Makefiles"), ("cmake", "make", "cc", "c++")),
    ("cmake", {}, ("-GNinja Multi-Config",), ("cmake", "ninja", "cc", "c++")),
    ("cmake", {"CC": "/opt/clang", "CXX": "clang++"}, (), ("cmake", "make", "/opt/clang", "clang++")),
    ("ament_python", {"CC": "clang"}, (), ()),
    ("python", {}, (), ()),
])
def test_build_tools(build_type: str, env: dict, args: tuple, tools: tuple) -> None:
    assert build_tools(build_type, env, args) == tools


def _options(tmp_path: Path, **fields) -> BuildOptions:
    return BuildOptions(build_base=tmp_path / "build", install_base=tmp_path / "install", **fields)


def test_forced_reasons_name_each_option(tmp_path: Path) -> None:
    assert forced_reasons(_options(tmp_path)) == []
    assert forced_reasons(_options(tmp_path, force=True, use_state=False)) == ["--no-cache", "--force"]
    assert forced_reasons(_options(tmp_path, cmake_target="install", cmake_clean_first=True)) == [
        "--cmake-target (a partial build is never recorded as up to date)", "--cmake-clean-first"]


def test_stale_reasons(tmp_path: Path) -> None:
    package = Package("p", Path("src/p"), "ros.ament_cmake")
    options = _options(tmp_path)
    parts = {"sources": {"a.c": "1:0"}}
    assert stale_reasons(package, PackageState("f", parts, {}, {}, {}), options) == ["never built"]
    assert stale_reasons(package, PackageState("f", parts, {}, {"fingerprint": None}, {}), options) == [
        "its last build did not succeed"]
    stored = {"fingerprint": "old", "parts": {"sources": {"a.c": "0:0"}}}
    assert stale_reasons(package, PackageState("f", parts, {}, stored, {}), options) == ["files changed: a.c"]
    assert stale_reasons(package, PackageState("f", parts, {}, {"fingerprint": "old", "parts": parts}, {}), options) == [
        "built by another version of roc"]
    same = {"fingerprint": "f", "parts": parts}
    assert stale_reasons(package, PackageState("f", parts, {}, same, {}), options) == [
        "its install is incomplete (files of its last install are missing)"]
    prefix = tmp_path / "install" / "p"
    for marker in (prefix / "share/colcon-core/packages/p", prefix / "share/p/package.dsv"):
        marker.parent.mkdir(parents=True, exist_ok=True)
        marker.write_text("")
    write_state(tmp_path / "build" / "p", "f", {}, parts)
    assert stale_reasons(package, PackageState("f", parts, {}, same, {}), options) == []
    assert stale_reasons(package, PackageState("f", parts, {}, same, {}), _options(tmp_path, force=True)) == ["--force"]


def _installed(tmp_path: Path, name: str) -> None:
    prefix = tmp_path / "install" / name
    for marker in (prefix / "share/colcon-core/packages" / name, prefix / "share" / name / "package.dsv"):
        marker.parent.mkdir(parents=True, exist_ok=True)
        marker.write_text("")


@pytest.mark.parametrize(("built_against", "interface_now", "reasons"), [
    ({"dep": "i1"}, "i1", []),  # rebuilt, the same interface: up to date, recorded anew
    ({"dep": "i1"}, "i2", ["dependency changed: dep"]),
    ({"dep": "i1"}, None, ["dependency to be built first: dep (then this package only if its interface changes)"]),
    ({}, "i1", ["dependency changed: dep"]),  # recorded by an older roc: not known
])
def test_a_dependency_counts_by_its_interface(tmp_path: Path, built_against: dict, interface_now: str | None,
                                              reasons: list[str]) -> None:
    package = Package("p", Path("src/p"), "ros.ament_cmake")
    _installed(tmp_path, "p")
    before = {"sources": {"a.c": "1:0"}, "dependencies": {"dep": "dep-f1"}}
    now = {"sources": {"a.c": "1:0"}, "dependencies": {"dep": "dep-f2"}}
    stored = {"fingerprint": "f1", "parts": before, "interfaces": built_against}
    state = PackageState("f2", now, {}, stored, {"dep": interface_now})
    assert stale_reasons(package, state, _options(tmp_path)) == reasons
    assert state.cut_off()


def test_a_dependency_interface_does_not_hide_other_changes(tmp_path: Path) -> None:
    package = Package("p", Path("src/p"), "ros.ament_cmake")
    _installed(tmp_path, "p")
    before = {"sources": {"a.c": "1:0"}, "dependencies": {"dep": "dep-f1"}, "generated": {"x.h": "1:0"}}
    stored = {"fingerprint": "f1", "parts": before, "interfaces": {"dep": "i1"}}
    for now, reason in (({**before, "sources": {"a.c": "2:0"}, "dependencies": {"dep": "dep-f2"}}, "files changed: a.c"),
                        ({"sources": {"a.c": "1:0"}, "dependencies": {"dep": "dep-f2"}}, "generated files removed: x.h")):
        assert reason in stale_reasons(package, PackageState("f2", now, {}, stored, {"dep": "i1"}), _options(tmp_path))
