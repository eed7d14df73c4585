"""Up-to-date checks end to end on a tiny plain-CMake workspace: what rebuilds, and the reasons roc gives
(in events.log and with --explain)."""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import pytest
from helpers.build import BIN, add_plain_package, in_sourced_shell, roc, ros_env

pytestmark = pytest.mark.slow

PACKAGE_XML = """<?xml version="1.0"?>
<package format="3">
  <name>{name}</name><version>0.0.1</version><description>d</description>
  <maintainer email="a@b.c">a</maintainer><license>MIT</license>
  {depends}
  <export><build_type>cmake</build_type></export>
</package>
"""
CMAKE = """cmake_minimum_required(VERSION 3.8)
project({name} C)
add_executable({name} main.c)
install(TARGETS {name} DESTINATION bin)
"""
# top depends on base; other stands alone
PACKAGES = {"base": (), "top": ("base",), "other": ()}


@pytest.fixture
def ws(tmp_path: Path) -> Path:
    for name, depends in PACKAGES.items():
        directory = tmp_path / "src" / name
        directory.mkdir(parents=True)
        depends_xml = "".join(f"<depend>{d}</depend>" for d in depends)
        (directory / "package.xml").write_text(PACKAGE_XML.format(name=name, depends=depends_xml))
        (directory / "CMakeLists.txt").write_text(CMAKE.format(name=name))
        (directory / "main.c").write_text("int main(void) { return 0; }\n")
    _build(tmp_path)
    assert _started(tmp_path) == {name: ("never built",) for name in PACKAGES}
    return tmp_path


def _build(ws: Path, *args: str, env: dict[str, str] | None = None) -> str:
    result = roc("work", "build", *args, cwd=ws, env=env)
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


def _started(ws: Path) -> dict[str, tuple[str, ...]]:
    """Each package that was built by the last build, with its reasons (from events.log)."""
    lines = (ws / "log" / "latest_build" / "events.log").read_text().splitlines()
    events = [json.loads(line) for line in lines]
    return {e["task"]: tuple(e["reasons"]) for e in events if e["event"] == "TaskStarted"}


def _explain(ws: Path, env: dict[str, str] | None = None) -> dict[str, list[str]]:
    result = roc("work", "build", "--explain", "--output", "json", cwd=ws, env=env)
    assert result.returncode == 0, result.stderr
    return {entry["package"]: entry["reasons"] for entry in json.loads(result.stdout)}


def test_editor_droppings_rebuild_nothing(ws: Path) -> None:
    source = ws / "src" / "base"
    for name in (".main.c.swp", "main.c~", "4913", ".#main.c", "#main.c#"):
        (source / name).write_text("editor state")
    assert "3 packages up to date (not rebuilt)" in _build(ws)
    assert _started(ws) == {}


def test_editing_a_source_rebuilds_it_and_its_dependents_with_the_reason(ws: Path) -> None:
    time.sleep(0.01)
    (ws / "src" / "base" / "main.c").write_text("int main(void) { return 1; }\n")
    (ws / "src" / "base" / "extra.h").write_text("\n")
    waits = "dependency to be built first: base (then this package only if its interface changes)"
    assert _explain(ws) == {"base": ["files added: extra.h", "files changed: main.c"], "other": [], "top": [waits]}
    text = roc("work", "build", "--explain", cwd=ws)
    assert text.stdout.splitlines() == ["base: files added: extra.h; files changed: main.c",
                                        "other: up to date", f"top: {waits}"]
    assert not (ws / "log" / "latest_build" / "events.log").read_text().count("files added")  # --explain built nothing
    _build(ws)
    assert _started(ws) == {"base": ("files added: extra.h", "files changed: main.c"),
                            "top": ("dependency changed: base",)}
    assert _explain(ws) == {"base": [], "other": [], "top": []}


def test_a_file_changed_within_the_second_of_its_last_install_is_installed(ws: Path) -> None:
    """CMake's install keeps a copy's time to the second and skips a file whose time matches."""
    source = ws / "src" / "base"
    with (source / "CMakeLists.txt").open("a") as cmake:
        cmake.write("install(FILES data.txt DESTINATION share/base)\n")
    second = int(time.time()) - 10
    (source / "data.txt").write_text("first\n")
    os.utime(source / "data.txt", (second + 0.2, second + 0.2))
    _build(ws)
    (source / "data.txt").write_text("again\n")
    os.utime(source / "data.txt", (second + 0.7, second + 0.7))
    _build(ws)
    assert (ws / "install" / "base" / "share" / "base" / "data.txt").read_text() == "again\n"
    assert _started(ws) == {"base": ("files changed: data.txt",), "top": ("dependency changed: base",)}


def _wrapper(directory: Path, tool: str) -> Path:
    """A script named ``tool`` that runs the real one found on PATH."""
    directory.mkdir(exist_ok=True)
    real = next(Path(p, tool) for p in os.environ["PATH"].split(os.pathsep) if os.access(Path(p, tool), os.X_OK))
    script = directory / tool
    script.write_text(f'#!/bin/sh\nexec {real} "$@"\n')
    script.chmod(0o755)
    return script


def test_another_build_tool_on_path_makes_cmake_packages_stale(ws: Path, tmp_path: Path) -> None:
    tools = tmp_path / "tools"
    _wrapper(tools, "make")
    env = ros_env()
    env["PATH"] = f"{tools}{os.pathsep}{env['PATH']}"
    expected = {"base": ["toolchain changed: tool make"], "other": ["toolchain changed: tool make"],
                "top": ["toolchain changed: tool make", "dependency changed: base"]}
    assert _explain(ws, env) == expected
    _build(ws, env=env)
    assert _started(ws) == {name: tuple(reasons) for name, reasons in expected.items()}
    assert _explain(ws, env) == {name: [] for name in PACKAGES}


def test_another_compiler_in_cc_makes_cmake_packages_stale(ws: Path, tmp_path: Path) -> None:
    compiler = _wrapper(tmp_path / "cc", "cc")
    env = ros_env(CC=str(compiler))
    reasons = _explain(ws, env)
    changed = f"toolchain changed: tool {compiler}, tool cc, variable CC"  # the compiler is now named by CC
    assert reasons == {"base": [changed], "other": [changed], "top": [changed, "dependency changed: base"]}
    _build(ws, env=env)
    assert _started(ws) == {name: tuple(r) for name, r in reasons.items()}


def test_a_rebuild_for_another_cc_compiles_with_it(ws: Path, tmp_path: Path) -> None:
    marker = tmp_path / "compiled-with-wrapper"
    compiler = tmp_path / "wrapped-cc"
    compiler.write_text(f'#!/bin/sh\necho ran >> "{marker}"\nexec cc "$@"\n')
    compiler.chmod(0o755)
    _build(ws, env=ros_env(CC=str(compiler)))
    assert set(_started(ws)) == set(PACKAGES)
    assert marker.exists()


@pytest.mark.slow
def test_changed_underlay_rebuilds_the_overlay(tmp_path):
    underlay, overlay = tmp_path / "underlay", tmp_path / "overlay"
    add_plain_package(underlay, "lib_a")
    add_plain_package(overlay, "app_b", depends="find_package(lib_a REQUIRED)\n")
    assert roc("work", "build", cwd=underlay).returncode == 0
    build = f"source {underlay}/install/setup.bash && {BIN}/roc work build"
    assert in_sourced_shell(overlay, build, setup="/dev/null", strict=False).returncode == 0
    again = in_sourced_shell(overlay, build, setup="/dev/null", strict=False)
    assert "1 package up to date" in again.stdout
    (underlay / "src" / "lib_a" / "value.txt").write_text("v2")
    assert roc("work", "build", cwd=underlay).returncode == 0
    rebuilt = in_sourced_shell(overlay, build, setup="/dev/null", strict=False)
    assert "Finished <<< app_b" in rebuilt.stdout, rebuilt.stdout


@pytest.mark.slow
def test_symlinked_sources_are_tracked(tmp_path):
    shared = tmp_path / "shared.txt"
    shared.write_text("v1")
    add_plain_package(tmp_path / "ws", "alpha")
    value = tmp_path / "ws" / "src" / "alpha" / "value.txt"
    value.unlink()
    value.symlink_to(shared)
    assert roc("work", "build", cwd=tmp_path / "ws").returncode == 0
    shared.write_text("v2")
    result = roc("work", "build", cwd=tmp_path / "ws")
    assert "Finished <<< alpha" in result.stdout
    assert (tmp_path / "ws" / "install" / "alpha" / "share" / "alpha" / "value.txt").read_text() == "v2"
