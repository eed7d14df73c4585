"""Incremental builds: what a change rebuilds, read from the events roc logged (no tool runs for an
up-to-date package)."""

from __future__ import annotations

import json
import shutil
import subprocess
import time
from pathlib import Path

import pytest
from helpers.build import BIN, copy_fixture, in_sourced_shell, roc, ros_env

pytestmark = pytest.mark.slow


def _events(ws) -> list[dict]:
    return [json.loads(line) for line in (ws / "log" / "latest_build" / "events.log").read_text().splitlines()]


def _built(ws) -> set[str]:
    """Packages whose tools ran in the last build."""
    return {e["task"] for e in _events(ws) if e["event"] == "CommandStarted"}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    ws = copy_fixture("build_small", tmp_path_factory.mktemp("inc") / "ws")
    result = roc("work", "build", cwd=ws)
    assert result.returncode == 0, result.stdout + result.stderr
    return ws


def test_noop_rebuild_runs_no_tool(built):
    result = roc("work", "build", cwd=built)
    assert result.returncode == 0
    assert _built(built) == set()
    assert "4 packages up to date (not rebuilt)" in result.stdout
    assert "Starting >>>" not in result.stdout


def test_an_edit_inside_a_library_rebuilds_its_package_only(built):
    """app links core's library, which it loads at run time: an edit of core's implementation changes
    nothing app would build, and app runs the new code without being relinked."""
    source = built / "src" / "core" / "src" / "core.cpp"
    original = source.read_text()
    source.write_text(original.replace("42", "43"))
    try:
        explained = roc("work", "build", "--explain", cwd=built).stdout
        assert "app: dependency to be built first: core (then this package only if its interface changes)" \
            in explained.splitlines(), explained
        assert roc("work", "build", cwd=built).returncode == 0
        assert _built(built) == {"core"}
        assert "core says 43" in in_sourced_shell(built, "install/app/lib/app/app").stdout
    finally:
        source.write_text(original)
    assert roc("work", "build", cwd=built).returncode == 0
    assert _built(built) == {"core"}  # back to the old content: a new build of it
    assert "core says 42" in in_sourced_shell(built, "install/app/lib/app/app").stdout
    source.touch()  # a new mtime with the same content changes nothing
    assert roc("work", "build", cwd=built).returncode == 0
    assert _built(built) == set()


@pytest.mark.parametrize("path, old, new", [
    ("src/core.cpp", "int core_value()", "int core_extra() { return 1; }\nint core_value()"),  # a symbol added
    ("include/core/core.hpp", "int core_value();", "int core_value();  // the answer"),  # a header edited
])
def test_a_change_to_a_librarys_interface_rebuilds_its_dependents(built, path, old, new):
    source = built / "src" / "core" / path
    original = source.read_text()
    source.write_text(original.replace(old, new))
    try:
        assert roc("work", "build", cwd=built).returncode == 0
        assert _built(built) == {"core", "app", "pyp"}  # pyp depends on core (exec_depend)
        reasons = {e["task"]: e["reasons"] for e in _events(built) if e["event"] == "TaskStarted"}
        assert reasons["app"] == ["dependency changed: core"]
    finally:
        source.write_text(original)
    assert roc("work", "build", cwd=built).returncode == 0
    assert _built(built) == {"core", "app", "pyp"}


def test_cmake_args_rebuild_the_cmake_packages_only(built):
    """pyp (Python) depends on core, whose rebuild with an unused variable installs the same files."""
    assert roc("work", "build", "--cmake-args", "-DROC_TEST_OPTION=1", cwd=built).returncode == 0
    assert _built(built) == {"core", "app", "plain"}
    assert roc("work", "build", "--cmake-args", "-DROC_TEST_OPTION=1", cwd=built).returncode == 0
    assert _built(built) == set()
    assert roc("work", "build", cwd=built).returncode == 0  # back to no arguments
    assert _built(built) == {"core", "app", "plain"}


def test_deleted_install_or_build_directory_rebuilds(built):
    shutil.rmtree(built / "install" / "plain")
    assert roc("work", "build", cwd=built).returncode == 0
    assert _built(built) == {"plain"}
    assert in_sourced_shell(built, "plain").stdout.strip() == "plain ok"
    shutil.rmtree(built / "build" / "app")
    assert roc("work", "build", cwd=built).returncode == 0
    assert _built(built) == {"app"}


def test_damaged_state_rebuilds_with_a_warning(built):
    state = built / "build" / "plain" / "roc_state.json"
    state.write_text(state.read_text()[: len(state.read_text()) // 2])
    result = roc("work", "build", cwd=built)
    assert result.returncode == 0
    assert "damaged build state" in result.stderr and "plain" in result.stderr
    assert _built(built) == {"plain"}


def test_failed_build_is_never_up_to_date(built):
    cmakelists = built / "src" / "plain" / "CMakeLists.txt"
    original = cmakelists.read_text()
    cmakelists.write_text(original + "\nmessage(FATAL_ERROR broken)\n")
    try:
        assert roc("work", "build", cwd=built).returncode == 1
    finally:
        cmakelists.write_text(original)
    assert roc("work", "build", cwd=built).returncode == 0
    assert _built(built) == {"plain"}


def test_force_and_no_cache(built):
    forced = roc("work", "build", "--force", "--packages-select", "plain", cwd=built)
    assert forced.returncode == 0 and _built(built) == {"plain"}, forced.stdout + forced.stderr
    # --no-cache records nothing, and what it installs may differ from what the old fingerprint
    # described: the next build must not trust that fingerprint.
    main_c = built / "src" / "plain" / "main.c"
    original = main_c.read_text()
    main_c.write_text(original.replace("plain ok", "plain changed"))
    try:
        uncached = roc("work", "build", "--no-cache", "--packages-select", "plain", cwd=built)
        assert uncached.returncode == 0 and _built(built) == {"plain"}, uncached.stdout + uncached.stderr
    finally:
        main_c.write_text(original)
    again = roc("work", "build", cwd=built)
    assert again.returncode == 0 and _built(built) == {"plain"}, again.stdout + again.stderr
    assert in_sourced_shell(built, "plain").stdout.strip() == "plain ok", again.stdout


def test_concurrent_builds_wait_for_each_other(tmp_path):
    ws = copy_fixture("build_small", tmp_path / "ws")
    command = [str(BIN / "roc"), "work", "build", "--packages-up-to", "app"]
    first = subprocess.Popen(command, cwd=ws, env=ros_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lock = ws / "build" / ".roc_lock"
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not (lock.exists() and f"pid {first.pid}" in lock.read_text()):
            time.sleep(0.05)
        second = subprocess.run(command, cwd=ws, env=ros_env(), capture_output=True, text=True, timeout=300)
        first_out, _ = first.communicate(timeout=300)
    finally:
        if first.poll() is None:
            first.kill()
    assert first.returncode == 0 and second.returncode == 0
    assert "waiting for it to finish" in second.stderr
    assert "2 packages up to date" in second.stdout  # the second found the first's results
    assert "core says 42" in in_sourced_shell(ws, "install/app/lib/app/app").stdout


def _reasons(ws) -> dict[str, list[str]]:
    return {e["task"]: e["reasons"] for e in _events(ws) if e["event"] == "TaskStarted"}


def test_only_the_tools_a_build_uses_count(built, tmp_path):
    """Issue 17.2: an unused ninja first on PATH rebuilds nothing (the generator is Unix Makefiles);
    another C++ compiler rebuilds the C++ packages. (More up-to-date cases: test_uptodate.py.)"""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    (bin_dir / "ninja").write_text("#!/bin/sh\nexit 1\n")
    (bin_dir / "ninja").chmod(0o755)
    env = ros_env(PATH=f"{bin_dir}:{ros_env()['PATH']}")
    assert roc("work", "build", cwd=built, env=env).returncode == 0
    assert _built(built) == set()  # Unix Makefiles: ninja is not a tool of these builds
    compiler = bin_dir / "c++"
    compiler.write_text(f"#!/bin/sh\nexec {shutil.which('c++')} \"$@\"\n")
    compiler.chmod(0o755)
    changed = roc("work", "build", cwd=built, env=ros_env(PATH=f"{bin_dir}:{ros_env()['PATH']}"))
    assert changed.returncode == 0, changed.stdout + changed.stderr
    reasons = _reasons(built)
    assert any(r.startswith("toolchain changed: ") and "tool c++" in r for r in reasons["core"]), reasons
    assert "pyp" not in reasons or not any("c++" in r for r in reasons["pyp"])  # a Python package uses no compiler
    assert roc("work", "build", cwd=built).returncode == 0  # back to the usual compiler


def _installed_links(prefix: Path) -> list[str]:
    return sorted(str(p.relative_to(prefix)) for p in prefix.rglob("*") if p.is_symlink())


@pytest.mark.slow
def test_switching_symlink_install_on_and_off_on_an_existing_build_base(tmp_path: Path) -> None:
    workspace = copy_fixture("build_small", tmp_path / "ws")
    core = workspace / "src" / "core"
    (core / "core_py").mkdir()
    (core / "core_py" / "__init__.py").write_text("VALUE = 1\n")
    cmake = (core / "CMakeLists.txt").read_text().replace(
        "ament_package()", "find_package(ament_cmake_python REQUIRED)\nament_python_install_package(core_py)\n"
                           "ament_package()")
    (core / "CMakeLists.txt").write_text(cmake)
    build = ("work", "build", "--packages-select", "core", "pyp")
    first = roc(*build, cwd=workspace)
    assert first.returncode == 0, first.stdout + first.stderr
    install = workspace / "install"
    assert _installed_links(install) == []
    on = roc(*build, "--symlink-install", cwd=workspace)
    assert on.returncode == 0, on.stdout + on.stderr  # was: "existing path cannot be removed: Is a directory"
    header = install / "core" / "include" / "core" / "core.hpp"
    assert header.is_symlink() and header.resolve() == (core / "include" / "core" / "core.hpp").resolve()
    assert any("pyp" in link for link in _installed_links(install / "pyp"))
    off = roc(*build, cwd=workspace)
    assert off.returncode == 0, off.stdout + off.stderr
    assert "AMENT_CMAKE_SYMLINK_INSTALL:BOOL=OFF" in (workspace / "build" / "core" / "CMakeCache.txt").read_text()
    assert _installed_links(install) == [] and header.is_file()
    assert (core / "core_py" / "__init__.py").read_text() == "VALUE = 1\n"
    site = next((install / "core" / "lib").glob("python*/site-packages"))
    assert (site / "core_py" / "__init__.py").read_text() == "VALUE = 1\n"
