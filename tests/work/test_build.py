"""roc work build end to end: real builds of a small workspace, sourced and run in a fresh shell."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import time
from pathlib import Path

import psutil
import pytest
from helpers.build import (
    BIN,
    add_cmake_package,
    colcon,
    comparable_install_files,
    copy_fixture,
    in_sourced_shell,
    package_dsv_files,
    roc,
    ros_env,
    sourced_values,
    without_own_underlay,
)

pytestmark = pytest.mark.slow


def test_build_then_source_and_run(tmp_path):
    # A path with a space: scripts and commands must quote everything.
    ws = copy_fixture("build_small", tmp_path / "my ws")
    result = roc("work", "build", "--parallel-workers", "2", cwd=ws)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Summary: 4 packages finished" in result.stdout
    for name in ("core", "app", "plain", "pyp"):
        assert f"Finished <<< {name}" in result.stdout
    ran = in_sourced_shell(ws, "install/app/lib/app/app; plain; install/pyp/lib/pyp/hello; "
                               "python -c 'import pyp.main as m; print(m.__file__)'")
    assert ran.returncode == 0, ran.stderr
    assert "app: core says 42" in ran.stdout and "plain ok" in ran.stdout and "hello from pyp" in ran.stdout
    assert f"{ws}/install/pyp/lib/python3.11/site-packages/pyp/main.py" in ran.stdout
    values = sourced_values(ws)
    assert "" not in values["LD_LIBRARY_PATH"].split(":")
    assert values["COLCON_PREFIX_PATH"] == "WS/install"
    # Logs and results as colcon leaves them.
    latest = ws / "log" / "latest_build"
    assert (latest / "core" / "stdout_stderr.log").is_file() and (latest / "events.log").is_file()
    assert (ws / "build" / "app" / "colcon_build.rc").read_text().strip() == "0"
    assert json.loads((ws / "build" / "app" / "roc_build_environment.json").read_text())["AMENT_PREFIX_PATH"]


@pytest.mark.skipif(shutil.which("zsh") is None, reason="zsh is not installed")
def test_setup_zsh_and_setup_sh(tmp_path):
    ws = copy_fixture("build_small", tmp_path / "ws")
    assert roc("work", "build", "--packages-up-to", "app", "--packages-select", "app", "core", cwd=ws).returncode == 0
    env = {"HOME": str(tmp_path), "PATH": "/usr/bin:/bin"}
    for command in (["zsh", "-f", "-c", "setopt nounset; source install/setup.zsh; install/app/lib/app/app"],
                    ["sh", "-c", "set -u; . install/setup.sh; install/app/lib/app/app"]):
        ran = subprocess.run(command, cwd=ws, env=env, capture_output=True, text=True, timeout=60)
        assert ran.returncode == 0 and "core says 42" in ran.stdout, (command, ran.stdout, ran.stderr)
    # sh cannot know where a sourced script is: away from the workspace it uses the build-time path.
    away = subprocess.run(["sh", "-c", f". '{ws}/install/setup.sh'; echo $CMAKE_PREFIX_PATH"], cwd=tmp_path,
                          env=env, capture_output=True, text=True, timeout=60)
    assert away.stdout.strip() == f"{ws}/install/app:{ws}/install/core"


@pytest.mark.colcon
def test_same_tree_and_environment_as_colcon(tmp_path):
    ours = copy_fixture("build_small", tmp_path / "roc")
    theirs = copy_fixture("build_small", tmp_path / "colcon")
    assert roc("work", "build", cwd=ours).returncode == 0
    result = colcon("build", cwd=theirs)
    assert result.returncode == 0, result.stdout + result.stderr
    assert comparable_install_files(ours / "install") == comparable_install_files(theirs / "install")
    assert package_dsv_files(ours / "install") == package_dsv_files(theirs / "install")
    ours_env = without_own_underlay(sourced_values(ours))
    theirs_env = sourced_values(theirs, strict=False)  # colcon's scripts are not `set -u` safe
    # colcon leaves an empty entry (the current directory) at the end of LD_LIBRARY_PATH; roc does not.
    theirs_env["LD_LIBRARY_PATH"] = theirs_env["LD_LIBRARY_PATH"].rstrip(":")
    assert ours_env == theirs_env


def test_merge_install_and_layout_mismatch(tmp_path):
    ws = copy_fixture("build_small", tmp_path / "ws")
    assert roc("work", "build", "--merge-install", cwd=ws).returncode == 0
    assert (ws / "install" / ".colcon_install_layout").read_text().strip() == "merged"
    ran = in_sourced_shell(ws, "install/lib/app/app; plain; install/lib/pyp/hello")
    assert ran.returncode == 0, ran.stderr
    assert "app: core says 42" in ran.stdout and "hello from pyp" in ran.stdout
    mixed = roc("work", "build", cwd=ws)
    assert mixed.returncode == 2
    assert "merged layout" in mixed.stderr and "--merge-install" in mixed.stderr


def test_symlink_install_shows_python_edits_without_rebuild(tmp_path):
    ws = copy_fixture("build_small", tmp_path / "ws")
    assert roc("work", "build", "--symlink-install", "--packages-up-to", "pyp", cwd=ws).returncode == 0
    assert in_sourced_shell(ws, "install/pyp/lib/pyp/hello").stdout.strip() == "hello from pyp"
    (ws / "src" / "pyp" / "pyp" / "main.py").write_text('def main():\n    print("edited")\n')
    assert in_sourced_shell(ws, "install/pyp/lib/pyp/hello").stdout.strip() == "edited"
    assert not (ws / "src" / "pyp" / "pyp.egg-info").exists()  # nothing written into the source tree


def _broken_workspace(tmp_path: Path) -> Path:
    ws = copy_fixture("build_small", tmp_path / "ws")
    add_cmake_package(ws, "broken",
                      "cmake_minimum_required(VERSION 3.8)\nproject(broken C)\nmessage(FATAL_ERROR \"on purpose\")\n")
    add_cmake_package(ws, "needs_broken", "cmake_minimum_required(VERSION 3.8)\nproject(needs_broken NONE)\n",
                      ("broken",))
    return ws


def test_failure_stops_the_build(tmp_path):
    ws = _broken_workspace(tmp_path)
    result = roc("work", "build", "--executor", "sequential", cwd=ws)
    assert result.returncode == 1
    assert "Failed   <<< broken" in result.stdout and "on purpose" in result.stdout
    assert "needs_broken" not in result.stdout.split("Summary:")[0].replace("--- ", "")
    assert (ws / "build" / "broken" / "colcon_build.rc").read_text().strip() == "1"
    again = roc("work", "list", "-n", "--packages-select-build-failed", cwd=ws)
    assert again.stdout.split() == ["broken"]


def test_continue_on_error_skips_only_dependents(tmp_path):
    ws = _broken_workspace(tmp_path)
    result = roc("work", "build", "--continue-on-error", cwd=ws)
    assert result.returncode == 1
    assert "1 package failed: broken" in result.stdout
    assert "skipped because a dependency failed: needs_broken (needs broken)" in result.stdout
    for name in ("core", "app", "plain", "pyp"):
        assert f"Finished <<< {name}" in result.stdout


def test_ctrl_c_stops_every_process(tmp_path):
    ws = copy_fixture("build_small", tmp_path / "ws")
    add_cmake_package(ws, "sleeper", "cmake_minimum_required(VERSION 3.8)\nproject(sleeper NONE)\n"
                                "add_custom_target(wait ALL COMMAND sleep 120)\n")
    process = subprocess.Popen([str(BIN / "roc"), "work", "build", "--packages-select", "sleeper"], cwd=ws,
                               env=ros_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        sleepers: list[psutil.Process] = []
        while time.monotonic() < deadline and not sleepers:
            time.sleep(0.2)
            try:
                children = psutil.Process(process.pid).children(recursive=True)
            except psutil.NoSuchProcess:
                break
            sleepers = [c for c in children if c.name() == "sleep"]
        assert sleepers, "the build never reached the sleep"
        tree = psutil.Process(process.pid).children(recursive=True)
        process.send_signal(signal.SIGINT)
        stdout, _ = process.communicate(timeout=30)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 130
    assert "Aborted  <<< sleeper" in stdout
    assert not [p for p in tree if p.is_running() and p.status() != psutil.STATUS_ZOMBIE]
    assert (ws / "build" / "sleeper" / "colcon_build.rc").read_text().strip() == "SIGINT"


@pytest.mark.colcon
@pytest.mark.parametrize("underlay_tool", ["colcon", "roc"])
def test_underlay_and_overlay_interoperate(tmp_path, underlay_tool):
    """A colcon-built underlay under a roc overlay, and the other way round."""
    underlay = copy_fixture("build_small", tmp_path / "underlay")
    overlay = tmp_path / "overlay"
    (overlay / "src").mkdir(parents=True)
    os.rename(underlay / "src" / "app", overlay / "src" / "app")
    build_underlay = colcon("build", cwd=underlay) if underlay_tool == "colcon" else roc("work", "build", cwd=underlay)
    assert build_underlay.returncode == 0, build_underlay.stdout + build_underlay.stderr
    overlay_tool = "roc" if underlay_tool == "colcon" else "colcon"
    command = ([str(BIN / "roc"), "work", "build"] if overlay_tool == "roc" else [str(BIN / "colcon"), "build"])
    built = in_sourced_shell(overlay, " ".join(command), setup=str(underlay / "install" / "setup.bash"), strict=False)
    assert built.returncode == 0, built.stdout + built.stderr
    ran = in_sourced_shell(overlay, "install/app/lib/app/app; plain; echo $COLCON_PREFIX_PATH", strict=False)
    assert ran.returncode == 0, ran.stderr
    assert "app: core says 42" in ran.stdout and "plain ok" in ran.stdout
    assert f"{overlay}/install:{underlay}/install" in ran.stdout
