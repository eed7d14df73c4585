"""The discovery cache gives the same answers as a fresh discovery, whatever changed in between."""

from __future__ import annotations

import os
import subprocess
import time

import pytest
from helpers.build import BIN


def _manifest(name: str, depends: str = "", extra: str = "") -> str:
    return (f'<?xml version="1.0"?><package format="3"><name>{name}</name><version>1.0.0</version>'
            f'<description>d</description><maintainer email="m@example.com">m</maintainer><license>MIT</license>'
            f"{depends}{extra}</package>")


@pytest.fixture
def ws(tmp_path, monkeypatch):
    cache = tmp_path / "cache"
    monkeypatch.setenv("ROC_CACHE_DIR", str(cache))
    root = tmp_path / "ws"
    for name, depends in (("a", ""), ("b", "<depend>a</depend>")):
        (root / "src" / name).mkdir(parents=True)
        (root / "src" / name / "package.xml").write_text(_manifest(name, depends))
    return root


def _list(ws, *args: str, env: dict | None = None) -> list[str]:
    result = subprocess.run([str(BIN / "roc"), "work", "list", "-t", "-n", *args], cwd=ws, capture_output=True,
                            text=True, env={**os.environ, **(env or {})})
    assert result.returncode == 0, result.stderr
    return result.stdout.split()


def _touch_later(path) -> None:
    """Make sure the change gets a new mtime even on coarse file systems."""
    time.sleep(0.01)
    stat = path.stat()
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1_000_000_000))


def test_cache_is_written_and_used(ws):
    assert _list(ws) == ["a", "b"]
    cache_files = list((ws.parent / "cache").glob("discovery-*.marshal"))
    assert len(cache_files) == 1
    assert _list(ws) == ["a", "b"]


def test_new_and_removed_packages(ws):
    assert _list(ws) == ["a", "b"]
    (ws / "src" / "c").mkdir()
    (ws / "src" / "c" / "package.xml").write_text(_manifest("c", "<depend>b</depend>"))
    assert _list(ws) == ["a", "b", "c"]
    (ws / "src" / "c" / "COLCON_IGNORE").write_text("")
    assert _list(ws) == ["a", "b"]
    (ws / "src" / "c" / "COLCON_IGNORE").unlink()
    assert _list(ws) == ["a", "b", "c"]


def test_edited_manifest(ws):
    assert _list(ws) == ["a", "b"]
    manifest = ws / "src" / "a" / "package.xml"
    manifest.write_text(_manifest("a", "<depend>b</depend>").replace("<depend>b</depend>", ""))
    (ws / "src" / "b" / "package.xml").write_text(_manifest("b"))
    (ws / "src" / "a" / "package.xml").write_text(_manifest("a", "<depend>b</depend>"))
    _touch_later(ws / "src" / "a" / "package.xml")
    _touch_later(ws / "src" / "b" / "package.xml")
    assert _list(ws) == ["b", "a"]


def test_condition_variables_are_part_of_the_key(ws):
    (ws / "src" / "a" / "package.xml").write_text(
        _manifest("a", '<depend condition="$ROC_TEST_FLAVOUR == x">b</depend>'))
    (ws / "src" / "b" / "package.xml").write_text(_manifest("b"))
    _touch_later(ws / "src" / "a" / "package.xml")
    assert _list(ws, env={"ROC_TEST_FLAVOUR": "x"}) == ["b", "a"]
    assert _list(ws, env={"ROC_TEST_FLAVOUR": "y"}) == ["a", "b"]
    assert _list(ws, env={"ROC_TEST_FLAVOUR": "x"}) == ["b", "a"]


def test_plain_cmake_dependencies_from_a_new_cmake_file(ws):
    plain = ws / "src" / "plain"
    (plain / "cmake").mkdir(parents=True)
    (plain / "CMakeLists.txt").write_text("cmake_minimum_required(VERSION 3.8)\nproject(plain)\n")
    assert _list(ws) == ["a", "plain", "b"]  # no dependencies yet: in the first layer
    (plain / "cmake" / "deps.cmake").write_text("find_package(b REQUIRED)\n")
    assert _list(ws) == ["a", "b", "plain"]
    info = subprocess.run([str(BIN / "roc"), "work", "info", "plain"], cwd=ws, capture_output=True, text=True)
    assert "    build: b\n    run: b\n" in info.stdout


def test_damaged_cache_is_ignored(ws):
    assert _list(ws) == ["a", "b"]
    for cache_file in (ws.parent / "cache").glob("discovery-*.marshal"):
        cache_file.write_bytes(b"{ not marshal data")
    assert _list(ws) == ["a", "b"]


def test_warnings_are_repeated_from_the_cache(ws):
    (ws / "src" / "py").mkdir()
    (ws / "src" / "py" / "package.xml").write_text(
        _manifest("py", extra="<export><build_type>ament_python</build_type></export>"))
    for _ in range(2):
        result = subprocess.run([str(BIN / "roc"), "work", "list"], cwd=ws, capture_output=True, text=True)
        assert "has build type ament_python but no setup.py" in result.stderr


def test_inputs_below_the_root_are_relative_and_others_absolute_and_both_are_checked(ws):
    """The cache checks its inputs from the root's directory (relative paths stat faster); a base path
    outside the root stays absolute, and an edit on either side is seen."""
    import marshal

    outside = ws.parent / "elsewhere"
    (outside / "c").mkdir(parents=True)
    (outside / "c" / "package.xml").write_text(_manifest("c"))
    assert sorted(_list(ws, "--base-paths", "src", str(outside))) == ["a", "b", "c"]
    (cache,) = (ws.parent / "cache").glob("discovery-*.marshal")
    inputs = marshal.loads(cache.read_bytes())["inputs"]
    assert "src/a/package.xml" in inputs and str(outside / "c" / "package.xml") in inputs
    (outside / "c" / "package.xml").write_text(_manifest("c0"))
    _touch_later(outside / "c" / "package.xml")
    assert sorted(_list(ws, "--base-paths", "src", str(outside))) == ["a", "b", "c0"]
    (ws / "src" / "a" / "package.xml").write_text(_manifest("a", "<depend>c0</depend>"))
    _touch_later(ws / "src" / "a" / "package.xml")
    assert _list(ws, "--base-paths", "src", str(outside)) == ["c0", "a", "b"]


def test_the_cached_order_is_colcons_also_when_packages_are_ignored_or_form_a_cycle(ws):
    (ws / "src" / "c").mkdir()
    (ws / "src" / "c" / "package.xml").write_text(_manifest("c"))
    for _ in range(2):  # the first run fills the cache, the second reads it
        assert _list(ws) == ["a", "c", "b"]  # layers: a c, then b
        assert _list(ws, "--packages-ignore", "a") == ["b", "c"]  # without a, b is in the first layer
    _touch_later(ws / "src" / "a" / "package.xml")
    (ws / "src" / "a" / "package.xml").write_text(_manifest("a", "<depend>b</depend>"))
    for _ in range(2):
        result = subprocess.run([str(BIN / "roc"), "work", "list", "-t"], cwd=ws, capture_output=True, text=True)
        assert result.returncode != 0 and "dependency cycle" in result.stderr, result.stderr
