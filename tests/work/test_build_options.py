"""roc work build options on quick plain-CMake packages: configure caching, targets, output, job budget."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from helpers.build import BIN, add_plain_package, roc, ros_env

pytestmark = pytest.mark.slow  # every test builds a workspace

SHOW_MAKEFLAGS = """cmake_minimum_required(VERSION 3.8)
project({name} C)
add_custom_target(show ALL COMMAND printenv MAKEFLAGS)
add_custom_target(only_here COMMAND echo only-here-ran)
install(FILES CMakeLists.txt DESTINATION share/{name})
"""


@pytest.fixture
def ws(tmp_path) -> Path:
    for name in ("alpha", "beta"):
        directory = tmp_path / "src" / name
        directory.mkdir(parents=True)
        (directory / "CMakeLists.txt").write_text(SHOW_MAKEFLAGS.format(name=name))
    (tmp_path / "src" / "beta" / "CMakeLists.txt").write_text(
        SHOW_MAKEFLAGS.format(name="beta").replace("add_custom_target(only_here COMMAND echo only-here-ran)\n", ""))
    return tmp_path


def _commands(ws: Path, package: str) -> str:
    return (ws / "log" / "latest_build" / package / "command.log").read_text()


def test_configure_runs_only_when_needed(ws):
    assert roc("work", "build", cwd=ws).returncode == 0
    root = ws.resolve()
    configure = f"cmake {root}/src/alpha -DCMAKE_INSTALL_PREFIX={root}/install/alpha"
    lines = _commands(ws, "alpha").splitlines()
    assert lines[:2] == [f"Invoking command in '{root}/build/alpha': {configure}",
                         f"Invoked command '{configure}' returned '0'"]
    assert lines[-2:] == [f"Invoking command in '{root}/build/alpha': cmake --install {root}/build/alpha",
                          f"Invoked command 'cmake --install {root}/build/alpha' returned '0'"]
    assert (ws / "build" / "alpha" / "cmake_args.last").read_text() == "None"
    assert roc("work", "build", "--force", cwd=ws).returncode == 0  # --force: build even if up to date
    assert "-DCMAKE_INSTALL_PREFIX" not in _commands(ws, "alpha")  # but no configure: nothing changed
    changed = roc("work", "build", "--cmake-args", "-DSOME_OPTION=ON", cwd=ws)
    assert changed.returncode == 0, changed.stderr
    assert "-DSOME_OPTION=ON" in _commands(ws, "alpha")
    assert (ws / "build" / "alpha" / "cmake_args.last").read_text() == "['-DSOME_OPTION=ON']"
    forced = roc("work", "build", "--cmake-args", "-DSOME_OPTION=ON", "--cmake-force-configure", cwd=ws)
    assert forced.returncode == 0 and "-DSOME_OPTION=ON" in _commands(ws, "alpha")


def test_cmake_target_and_skip_unavailable(ws):
    assert roc("work", "build", cwd=ws).returncode == 0
    missing = roc("work", "build", "--cmake-target", "only_here", cwd=ws)
    assert missing.returncode == 1 and "no target 'only_here'" in missing.stdout
    result = roc("work", "build", "--cmake-target", "only_here", "--cmake-target-skip-unavailable",
                 "--event-handlers", "console_cohesion+", cwd=ws)
    assert result.returncode == 0, result.stdout
    assert "only-here-ran" in result.stdout


def test_global_job_budget_is_one_jobserver(ws):
    result = roc("work", "build", "-j", "3", "--event-handlers", "console_direct+", cwd=ws)
    assert result.returncode == 0, result.stderr
    flags = [line for line in result.stdout.splitlines() if "--jobserver-auth=" in line]
    assert len(flags) == 2 and all("-j3" in f for f in flags), result.stdout
    assert len({f.split("--jobserver-auth=")[1] for f in flags}) == 1  # the same jobserver for both packages


def test_json_events_for_ci(ws):
    result = roc("work", "build", "--output", "json", cwd=ws)
    assert result.returncode == 0
    events = [json.loads(line) for line in result.stdout.splitlines()]
    kinds = {e["event"] for e in events}
    assert {"TaskQueued", "TaskStarted", "CommandStarted", "TaskOutput", "TaskFinished", "RunFinished"} <= kinds
    assert sorted(e["task"] for e in events if e["event"] == "TaskFinished") == ["alpha", "beta"]


def test_quiet_handlers_and_no_logs(ws):
    result = roc("work", "build", "--event-handlers", "console_start_end-", "summary-", "--log-base", "/dev/null",
                 cwd=ws)
    assert result.returncode == 0 and result.stdout == ""
    assert not (ws / "log").exists()


@pytest.mark.parametrize("option", [["--test-result-base", "x"], ["--catkin-cmake-args", "-DX=1"], ["--catkin-skip-building-tests"],
                                    ["--event-handlers", "compile_commands+"], ["--event-handlers", "nonsense+"]])
def test_unsupported_options_are_rejected(ws, option):
    result = roc("work", "build", *option, cwd=ws)
    assert result.returncode == 2
    assert result.stderr.startswith("roc") and " error: " in result.stderr and len(result.stderr.splitlines()) == 1
    assert option[0].split("+")[0] in result.stderr or option[1].split("+")[0] in result.stderr  # names it
    assert not (ws / "build").exists()


def test_positional_names_mean_up_to(ws):
    result = roc("work", "build", "beta", cwd=ws)
    assert result.returncode == 0
    assert "Starting >>> beta" in result.stdout and "alpha" not in result.stdout


def test_env_prints_and_runs_the_build_environment(ws):
    assert roc("work", "build", cwd=ws).returncode == 0
    printed = roc("work", "env", "alpha", "--all", cwd=ws)
    assert printed.returncode == 0 and "export AMENT_PREFIX_PATH=" in printed.stdout
    ran = roc("work", "env", "alpha", "--", "sh", "-c", "echo $AMENT_PREFIX_PATH", cwd=ws / "src" / "alpha")
    assert ran.returncode == 0 and ran.stdout.strip() and "using workspace root" in ran.stderr
    unknown = roc("work", "env", "gamma", cwd=ws)
    assert unknown.returncode == 2 and "gamma" in unknown.stderr


@pytest.mark.skipif(shutil.which("ninja", path=str(BIN)) is None and shutil.which("ninja") is None,
                    reason="ninja is not installed")
def test_cmake_generator_is_respected(tmp_path):
    ws = tmp_path
    for name in ("alpha", "beta"):
        (ws / "src" / name).mkdir(parents=True)
        (ws / "src" / name / "CMakeLists.txt").write_text(
            f"cmake_minimum_required(VERSION 3.8)\nproject({name} NONE)\n"
            f"install(FILES CMakeLists.txt DESTINATION share/{name})\n")
    env = {**ros_env(), "CMAKE_GENERATOR": "Ninja"}
    result = roc("work", "build", "-j", "4", "--parallel-workers", "2", cwd=ws, env=env)
    assert result.returncode == 0, result.stdout + result.stderr
    assert (ws / "build" / "alpha" / "build.ninja").is_file()
    # ninja cannot join the make jobserver: each of the 2 packages gets half of the budget of 4
    assert "--build" in _commands(ws, "alpha") and "-- -j2" in _commands(ws, "alpha")
    assert (ws / "install" / "alpha" / "share" / "alpha" / "CMakeLists.txt").is_file()


@pytest.mark.parametrize("args, words", [
    (["--build-base", "afile"], ["afile"]),
    (["-j", "0"], ["-j"]),
    (["--log-base", "afile"], ["afile"]),
])
def test_bad_bases_and_numbers_are_one_line_errors(tmp_path, args, words):
    add_plain_package(tmp_path, "alpha")
    (tmp_path / "afile").write_text("")
    result = roc("work", "build", *args, cwd=tmp_path)
    assert result.returncode in (1, 2)
    assert result.stderr.startswith("roc: error:") and "internal error" not in result.stderr
    assert all(word in result.stderr for word in words), result.stderr


@pytest.mark.slow
def test_not_processed_packages_are_counted(tmp_path):
    add_plain_package(tmp_path, "a")
    (tmp_path / "src" / "a" / "CMakeLists.txt").write_text("message(FATAL_ERROR no)\n")
    add_plain_package(tmp_path, "b", depends="find_package(a)\n")
    result = roc("work", "build", cwd=tmp_path)
    assert result.returncode == 1 and "1 package not processed" in result.stdout


def test_command_line_cmake_args_replace_configured_ones(tmp_path):
    add_plain_package(tmp_path, "alpha")
    (tmp_path / "roc.toml").write_text('[build]\ncmake-args = ["-DFROM_TOML=1"]\n')
    assert roc("work", "build", "--cmake-args", "-DFROM_CLI=1", cwd=tmp_path).returncode == 0
    log = (tmp_path / "log" / "latest_build" / "alpha" / "command.log").read_text()
    assert "-DFROM_CLI=1" in log and "-DFROM_TOML=1" not in log
