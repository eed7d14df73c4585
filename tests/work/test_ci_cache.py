"""CI caching: a stable key, export, import into a clone at another path, and a build that skips."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from helpers.build import FIXTURES, add_plain_package, copy_fixture, in_sourced_shell, roc

pytestmark = pytest.mark.slow


def _started(ws) -> set[str]:
    lines = (ws / "log" / "latest_build" / "events.log").read_text().splitlines()
    return {json.loads(line)["task"] for line in lines if json.loads(line)["event"] == "TaskStarted"}


def _clone(tmp_path, name):
    """What a CI runner has: the sources in a new directory, nothing built."""
    clone = tmp_path / name
    shutil.copytree(FIXTURES / "build_small" / "src", clone / "src")
    return clone


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    base = tmp_path_factory.mktemp("cache")
    ws = copy_fixture("build_small", base / "original")
    assert roc("work", "build", cwd=ws).returncode == 0
    result = roc("work", "cache", "export", str(base / "cache"), cwd=ws)
    assert result.returncode == 0 and "exported 4" in result.stdout, result.stdout + result.stderr
    return ws, base / "cache"


def test_key_is_stable_across_clones_and_follows_changes(exported, tmp_path):
    original, _ = exported
    key = roc("work", "cache", "key", cwd=original).stdout.strip()
    clone = _clone(tmp_path, "clone")
    assert key.startswith("roc-") and roc("work", "cache", "key", cwd=clone).stdout.strip() == key
    (clone / "src" / "plain" / "main.c").write_text((clone / "src" / "plain" / "main.c").read_text() + "\n")
    assert roc("work", "cache", "key", cwd=clone).stdout.strip() != key
    assert roc("work", "cache", "key", "--cmake-args", "-DX=1", cwd=original).stdout.strip() != key


def test_import_into_a_clone_then_build_skips_everything(exported, tmp_path):
    _, cache = exported
    clone = _clone(tmp_path / "elsewhere", "ci clone")  # another directory, with a space
    imported = roc("work", "cache", "import", str(cache), cwd=clone)
    assert imported.returncode == 0, imported.stderr
    assert "imported 4 package(s)" in imported.stdout
    built = roc("work", "build", cwd=clone)
    assert built.returncode == 0, built.stdout + built.stderr
    assert _started(clone) == set() and "4 packages up to date" in built.stdout
    ran = in_sourced_shell(clone, "install/app/lib/app/app; plain; install/pyp/lib/pyp/hello; "
                                  "python -c 'import pyp; print(pyp.__file__)'")
    assert ran.returncode == 0, ran.stderr
    assert "core says 42" in ran.stdout and "plain ok" in ran.stdout and "hello from pyp" in ran.stdout
    assert f"{clone}/install/pyp/lib/python3.11/site-packages/pyp/__init__.py" in ran.stdout
    assert str(exported[0]) not in (clone / "install" / "core" / "share" / "core" / "package.sh").read_text()


def test_damaged_entry_is_ignored_and_rebuilt(exported, tmp_path):
    _, cache = exported
    damaged = tmp_path / "damaged"
    shutil.copytree(cache, damaged)
    index = json.loads((damaged / "index.json").read_text())
    archive = damaged / "objects" / f"{index['packages']['plain']['fingerprint']}.tar.gz"
    archive.write_bytes(archive.read_bytes()[:100])  # a partial upload
    clone = _clone(tmp_path, "clone")
    imported = roc("work", "cache", "import", str(damaged), cwd=clone)
    assert imported.returncode == 0 and "imported 3 package(s)" in imported.stdout
    assert "damaged cache entry" in imported.stderr and "plain" in imported.stderr
    assert roc("work", "build", cwd=clone).returncode == 0
    assert _started(clone) == {"plain"}


def test_bad_usage(tmp_path):
    ws = _clone(tmp_path, "ws")
    missing_path = roc("work", "cache", "export", cwd=ws)
    assert missing_path.returncode == 2 and "needs the cache directory" in missing_path.stderr
    not_a_cache = roc("work", "cache", "import", str(tmp_path), cwd=ws)
    assert not_a_cache.returncode == 1 and "not a usable roc cache" in not_a_cache.stderr


@pytest.mark.slow
def test_cache_export_says_what_it_left_out_and_why(tmp_path: Path) -> None:
    workspace = tmp_path / "ws"
    add_plain_package(workspace, "alpha", None)
    add_plain_package(workspace, "beta", None, "find_package(alpha REQUIRED)\n")
    add_plain_package(workspace, "fixed", None)
    with (workspace / "src" / "fixed" / "CMakeLists.txt").open("a") as cmake:
        cmake.write('file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/where.txt "${CMAKE_INSTALL_PREFIX}")\n'
                    "install(FILES ${CMAKE_CURRENT_BINARY_DIR}/where.txt DESTINATION share/fixed)\n")
    add_plain_package(workspace, "never_built", None)
    built = roc("work", "build", "--packages-skip", "never_built", cwd=workspace)
    assert built.returncode == 0, built.stdout + built.stderr
    with (workspace / "src" / "alpha" / "CMakeLists.txt").open("a") as cmake:
        cmake.write("# changed after the build\n")
    result = roc("work", "cache", "export", str(tmp_path / "cache"), cwd=workspace)
    assert result.returncode == 0, result.stderr
    assert result.stdout == f"exported 1 up-to-date package(s) to {tmp_path / 'cache'}\n"
    assert result.stderr.splitlines() == [
        f"  fixed: import can restore it only into {workspace} (share/fixed/where.txt holds that path)",
        "  not exported: alpha: not up to date (it changed since its last build; build it first)",
        "  not exported: beta: not up to date (it changed since its last build; build it first)",
        "  not exported: never_built: not built successfully yet",
    ]
    index = json.loads((tmp_path / "cache" / "index.json").read_text())
    assert sorted(index["packages"]) == ["fixed"]
