"""Regressions found in review: permissions, odd paths, underlays, symlinks, names, bad input."""

from __future__ import annotations

import json
import shlex
import stat
import subprocess
import time

import pytest
from build_helpers import BIN, in_sourced_shell, roc, ros_env


def _plain(ws, name: str, text: str = "v1", depends: str = "") -> None:
    directory = ws / "src" / name
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "value.txt").write_text(text)
    (directory / "CMakeLists.txt").write_text(
        f"cmake_minimum_required(VERSION 3.8)\nproject({name} NONE)\n{depends}"
        f"install(FILES value.txt DESTINATION share/{name})\n"
        f"file(WRITE ${{CMAKE_CURRENT_BINARY_DIR}}/{name}Config.cmake \"\")\n"
        f"install(FILES ${{CMAKE_CURRENT_BINARY_DIR}}/{name}Config.cmake DESTINATION share/{name}/cmake)\n")


@pytest.mark.slow
def test_generated_files_are_readable_by_others(tmp_path):
    _plain(tmp_path, "alpha")
    assert roc("work", "build", cwd=tmp_path).returncode == 0
    for path in (tmp_path / "install" / "setup.sh", tmp_path / "install" / "alpha" / "share" / "alpha" / "package.sh"):
        assert stat.S_IMODE(path.stat().st_mode) & 0o044 == 0o044, path


@pytest.mark.slow
def test_posix_sh_with_spaces_and_non_ascii_in_the_path(tmp_path):
    ws = tmp_path / "my wörk $space"
    _plain(ws, "alpha")
    assert roc("work", "build", cwd=ws).returncode == 0
    result = subprocess.run(["sh", "-c", f'. {shlex.quote(str(ws))}/install/setup.sh; echo "$CMAKE_PREFIX_PATH"'],
                            cwd=tmp_path,
                            capture_output=True, text=True, env={"PATH": "/usr/bin:/bin"})
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == f"{ws}/install/alpha"


@pytest.mark.slow
def test_changed_underlay_rebuilds_the_overlay(tmp_path):
    underlay, overlay = tmp_path / "underlay", tmp_path / "overlay"
    _plain(underlay, "lib_a")
    _plain(overlay, "app_b", depends="find_package(lib_a REQUIRED)\n")
    assert roc("work", "build", cwd=underlay).returncode == 0
    build = f"source {underlay}/install/setup.bash && {BIN}/roc work build"
    assert in_sourced_shell(overlay, build, setup="/dev/null", strict=False).returncode == 0
    again = in_sourced_shell(overlay, build, setup="/dev/null", strict=False)
    assert "1 package up to date" in again.stdout
    time.sleep(1.1)  # CMake's install compares timestamps to the second
    (underlay / "src" / "lib_a" / "value.txt").write_text("v2")
    assert roc("work", "build", cwd=underlay).returncode == 0
    rebuilt = in_sourced_shell(overlay, build, setup="/dev/null", strict=False)
    assert "Finished <<< app_b" in rebuilt.stdout, rebuilt.stdout


@pytest.mark.slow
def test_symlinked_sources_are_tracked(tmp_path):
    shared = tmp_path / "shared.txt"
    shared.write_text("v1")
    _plain(tmp_path / "ws", "alpha")
    value = tmp_path / "ws" / "src" / "alpha" / "value.txt"
    value.unlink()
    value.symlink_to(shared)
    assert roc("work", "build", cwd=tmp_path / "ws").returncode == 0
    time.sleep(1.1)  # CMake's install compares timestamps to the second
    shared.write_text("v2")
    result = roc("work", "build", cwd=tmp_path / "ws")
    assert "Finished <<< alpha" in result.stdout
    assert (tmp_path / "ws" / "install" / "alpha" / "share" / "alpha" / "value.txt").read_text() == "v2"


def test_unusable_package_name_is_an_error(tmp_path):
    (tmp_path / "src" / "weird").mkdir(parents=True)
    (tmp_path / "src" / "weird" / "colcon.pkg").write_text(json.dumps({"name": "we$(touch PWNED)ird",
                                                                       "type": "cmake"}))
    result = roc("work", "build", cwd=tmp_path)
    assert result.returncode == 1 and "is not usable" in result.stderr
    assert not (tmp_path / "PWNED").exists() and not (tmp_path / "install").exists()


@pytest.mark.slow
def test_unsupported_build_type_is_skipped_with_a_warning(tmp_path):
    (tmp_path / "src" / "rusty").mkdir(parents=True)
    (tmp_path / "src" / "rusty" / "package.xml").write_text(
        '<package format="3"><name>rusty</name><version>1.0.0</version><description>d</description>'
        '<maintainer email="m@example.com">m</maintainer><license>MIT</license>'
        "<export><build_type>ament_cargo</build_type></export></package>")
    _plain(tmp_path, "alpha")
    result = roc("work", "build", cwd=tmp_path)
    assert result.returncode == 0 and "'ros.ament_cargo'" in result.stderr and "skipped" in result.stderr
    assert "Finished <<< alpha" in result.stdout


@pytest.mark.parametrize("args, words", [
    (["--build-base", "afile"], ["afile"]),
    (["-j", "0"], ["-j"]),
    (["--log-base", "afile"], ["afile"]),
])
def test_bad_bases_and_numbers_are_one_line_errors(tmp_path, args, words):
    _plain(tmp_path, "alpha")
    (tmp_path / "afile").write_text("")
    result = roc("work", "build", *args, cwd=tmp_path)
    assert result.returncode in (1, 2)
    assert result.stderr.startswith("roc: error:") and "internal error" not in result.stderr
    assert all(word in result.stderr for word in words), result.stderr


@pytest.mark.slow
def test_not_processed_packages_are_counted(tmp_path):
    _plain(tmp_path, "a")
    (tmp_path / "src" / "a" / "CMakeLists.txt").write_text("message(FATAL_ERROR no)\n")
    _plain(tmp_path, "b", depends="find_package(a)\n")
    result = roc("work", "build", cwd=tmp_path)
    assert result.returncode == 1 and "1 package not processed" in result.stdout


def test_command_line_cmake_args_replace_configured_ones(tmp_path):
    _plain(tmp_path, "alpha")
    (tmp_path / "roc.toml").write_text('[build]\ncmake-args = ["-DFROM_TOML=1"]\n')
    assert roc("work", "build", "--cmake-args", "-DFROM_CLI=1", cwd=tmp_path).returncode == 0
    log = (tmp_path / "log" / "latest_build" / "alpha" / "command.log").read_text()
    assert "-DFROM_CLI=1" in log and "-DFROM_TOML=1" not in log


def test_env_output_can_be_evaluated_with_exported_functions(tmp_path):
    _plain(tmp_path, "alpha")
    assert roc("work", "build", cwd=tmp_path).returncode == 0
    env = {**ros_env(), "BASH_FUNC_f%%": "() {  :\n}"}
    printed = roc("work", "env", "alpha", "--all", cwd=tmp_path, env=env)
    assert printed.returncode == 0 and "BASH_FUNC" not in printed.stdout
    evaluated = subprocess.run(["bash", "-c", 'eval "$1" && echo ok', "_", printed.stdout], capture_output=True,
                               text=True)
    assert evaluated.stdout.strip() == "ok", evaluated.stderr


def test_colcon_meta_values_are_type_checked(tmp_path):
    _plain(tmp_path, "alpha")
    (tmp_path / "colcon.meta").write_text('{"names": {"alpha": {"cmake-args": "-DX=1"}}}')
    result = roc("work", "build", cwd=tmp_path)
    assert result.returncode == 2 and "colcon.meta" in result.stderr and "list of strings" in result.stderr
