"""``roc work test`` against ``colcon test`` on the ``testing`` fixture (gtest, ament_cmake_pytest, pytest in
an ament_python package, CTest in a plain CMake package, a package without tests); cached results;
Ctrl+C on a hanging test; clean then build."""

from __future__ import annotations

import json
import re
import signal
import subprocess
import time
from pathlib import Path

import psutil
import pytest
from helpers.build import BIN, colcon, copy_fixture, roc, ros_env

pytestmark = pytest.mark.slow
FAILING = {"t_cmake_pytest", "t_plain", "t_py"}


def _results(tool, workspace: Path) -> str:
    """``test-result --all`` with CTest's time-stamped directories made comparable."""
    result = tool("work", "test-result", "--all", cwd=workspace) if tool is roc else \
        colcon("test-result", "--all", cwd=workspace)
    return re.sub(r"Testing/\d{8}-\d{4}/", "Testing/STAMP/", result.stdout)


def _rc_files(workspace: Path) -> dict[str, str]:
    return {p.parent.name: p.read_text() for p in (workspace / "build").glob("*/colcon_test.rc")}


def _commands_by_package(stdout: str) -> set[str]:
    events = [json.loads(line) for line in stdout.splitlines() if line.startswith("{")]
    return {e["task"] for e in events if e["event"] == "CommandStarted"}


def _reasons(stdout: str) -> dict[str, list[str]]:
    """Why each test task ran (``--output json``); test tasks are of kind ``test``."""
    events = [json.loads(line) for line in stdout.splitlines() if line.startswith("{")]
    assert {e["kind"] for e in events if e["task"]} <= {"test"}
    return {e["task"]: e["reasons"] for e in events if e["event"] == "TaskStarted"}


@pytest.mark.distro
def test_results_equal_colcon_and_are_cached(tmp_path: Path) -> None:
    workspace = copy_fixture("testing", tmp_path / "ws")
    built = roc("work", "build", cwd=workspace)
    assert built.returncode == 0, built.stdout + built.stderr

    expected = colcon("test", cwd=workspace)
    assert expected.returncode == 0, expected.stdout + expected.stderr
    colcon_results, colcon_rc = _results(colcon, workspace), _rc_files(workspace)
    assert "Summary: 12 tests, 0 errors, 4 failures, 2 skipped" in colcon_results
    assert colcon_rc == {"t_cmake_pytest": "test failures\n", "t_gtest": "0\n", "t_notests": "0\n",
                         "t_plain": "test failures\n", "t_py": "test failures\n"}

    actual = roc("work", "test", "--force", cwd=workspace)
    assert actual.returncode == 0, actual.stdout + actual.stderr
    assert "3 packages had test failures: t_cmake_pytest t_plain t_py" in actual.stdout
    assert "Finished <<< t_plain [" in actual.stdout and "]\t[ with test failures ]\n" in actual.stdout
    assert _results(colcon, workspace) == colcon_results
    assert _results(roc, workspace) == colcon_results
    assert _rc_files(workspace) == colcon_rc
    latest = workspace / "log" / "latest_test"
    assert sorted(p.name for p in latest.iterdir()) == ["events.log", "t_cmake_pytest", "t_gtest", "t_plain", "t_py"]
    assert (latest / "t_gtest" / "stdout_stderr.log").is_file() and not (latest / "t_gtest" / "test").exists()
    events = [json.loads(line) for line in (latest / "events.log").read_text().splitlines()]
    assert {e["kind"] for e in events if e["task"]} == {"test"}
    assert {e["task"] for e in events if e["event"] == "TestFailures"} == FAILING
    assert {e["task"]: e["reasons"] for e in events if e["event"] == "TaskStarted"} == {
        name: ["--force"] for name in FAILING | {"t_gtest", "t_notests"}}

    # Passing packages are cached, failing ones run again.
    second = roc("work", "test", "--output", "json", cwd=workspace)
    assert second.returncode == 0
    assert _commands_by_package(second.stdout) == FAILING
    assert _reasons(second.stdout) == {name: ["failed last time"] for name in FAILING}
    assert _results(roc, workspace) == colcon_results
    # Only passing packages: no test process at all.
    passing = roc("work", "test", "t_gtest", "t_notests", "--output", "json", cwd=workspace)
    assert _commands_by_package(passing.stdout) == set()
    text = roc("work", "test", "t_gtest", cwd=workspace)
    assert "1 package cached (passed before, not tested again): t_gtest" in text.stdout
    # Editing a test reruns that package; --force reruns everything.
    test_source = workspace / "src" / "t_gtest" / "test" / "test_math.cpp"
    test_source.write_text(test_source.read_text() + "// edited\n")
    edited = roc("work", "test", "--output", "json", cwd=workspace)
    assert _commands_by_package(edited.stdout) == FAILING | {"t_gtest"}
    assert _reasons(edited.stdout)["t_gtest"] == ["files changed: test/test_math.cpp"]
    forced = roc("work", "test", "--force", "--output", "json", cwd=workspace)
    assert _commands_by_package(forced.stdout) == FAILING | {"t_gtest"}  # t_notests has no CTest tests

    # Selection by the last test results, and the exit code on test failures.
    failures = roc("work", "test", "--packages-select-test-failures", "--return-code-on-test-failure",
                   "--output", "json", cwd=workspace)
    assert failures.returncode == 1 and _commands_by_package(failures.stdout) == FAILING
    skip_passed = roc("work", "test", "--packages-skip-test-passed", "--force", "--output", "json", cwd=workspace)
    assert _commands_by_package(skip_passed.stdout) == FAILING


HANGING_TEST = """import os, subprocess, time
from pathlib import Path


def test_hangs():
    child = subprocess.Popen(["sleep", "1000"])
    Path(os.environ["PIDS_FILE"]).write_text(f"{os.getpid()} {child.pid}")
    time.sleep(1000)
"""


def _python_package(workspace: Path, name: str, test: str) -> None:
    package = workspace / "src" / name
    (package / name).mkdir(parents=True)
    (package / name / "__init__.py").write_text("")
    (package / "test").mkdir()
    (package / "test" / "test_it.py").write_text(test)
    (package / "package.xml").write_text(
        f'<?xml version="1.0"?><package format="3"><name>{name}</name><version>0.1.0</version>'
        '<description>d</description><maintainer email="m@example.com">m</maintainer><license>MIT</license>'
        '<export><build_type>ament_python</build_type></export></package>\n')
    (package / "setup.py").write_text(
        f'from setuptools import setup\nsetup(name="{name}", version="0.1.0", packages=["{name}"], '
        'tests_require=["pytest"])\n')


def test_ctrl_c_stops_a_hanging_test_and_its_process_tree(tmp_path: Path) -> None:
    workspace = tmp_path / "ws"
    _python_package(workspace, "t_hang", HANGING_TEST)
    assert roc("work", "build", cwd=workspace).returncode == 0
    pids_file = tmp_path / "pids"
    process = subprocess.Popen([str(BIN / "roc"), "work", "test"], cwd=workspace,
                               env=ros_env(PIDS_FILE=str(pids_file)), stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while not pids_file.exists() or not pids_file.read_text():
            assert time.monotonic() < deadline and process.poll() is None, "the test never started"
            time.sleep(0.1)
        pids = [int(pid) for pid in pids_file.read_text().split()]
        process.send_signal(signal.SIGINT)
        stdout, _ = process.communicate(timeout=30)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 130, stdout
    assert "Aborted  <<< t_hang" in stdout
    for pid in pids:
        assert not psutil.pid_exists(pid) or psutil.Process(pid).status() == psutil.STATUS_ZOMBIE
    assert (workspace / "build" / "t_hang" / "colcon_test.rc").read_text() == "SIGINT\n"


def test_clean_then_build_rebuilds_what_was_removed(tmp_path: Path) -> None:
    workspace = tmp_path / "ws"
    _python_package(workspace, "t_a", "def test_ok():\n    pass\n")
    _python_package(workspace, "t_b", "def test_ok():\n    pass\n")
    assert roc("work", "build", cwd=workspace).returncode == 0
    tested = roc("work", "test", cwd=workspace)
    assert tested.returncode == 0 and (workspace / "build" / "t_a" / "pytest.xml").exists()
    cleaned = roc("work", "clean", "packages", "t_a", "-y", cwd=workspace)
    assert cleaned.returncode == 0, cleaned.stderr
    assert not (workspace / "install" / "t_a").exists() and (workspace / "install" / "t_b").exists()
    assert "t_a" not in (workspace / "install" / "local_setup.sh").read_text()
    rebuilt = roc("work", "build", cwd=workspace)
    assert "Starting >>> t_a" in rebuilt.stdout and "Starting >>> t_b" not in rebuilt.stdout
    assert roc("work", "test", "--output", "json", cwd=workspace).returncode == 0
    assert (workspace / "build" / "t_a" / "pytest.xml").exists()



def test_tests_that_cannot_start_say_why_on_the_console_and_in_test_result(tmp_path: Path) -> None:
    """pytest exits 2 when it cannot import a test file, 5 when it collected no test: colcon says only
    "exited with code 2" (or nothing), the reason stays in log/latest_test/<pkg>/stdout_stderr.log.
    my_node's linter tests import ament_copyright, ament_flake8 and ament_pep257 (as ``ros2 pkg create``'s
    do), which the PyPI wheels lack; my_tools's only test skips itself without ament_flake8."""
    workspace = copy_fixture("tests_not_started", tmp_path / "ws")
    assert roc("work", "build", cwd=workspace).returncode == 0
    reasons = [f"error collecting test/test_{linter}.py: ModuleNotFoundError: No module named 'ament_{linter}'"
               for linter in ("copyright", "flake8", "pep257")]
    skipped = ("skipped collecting test/test_flake8.py: could not import 'ament_flake8.main': "
               "No module named 'ament_flake8'")

    tested = roc("work", "test", cwd=workspace)
    assert tested.returncode == 1
    failed = f"pytest exited with code 2: {reasons[0]} (and 2 more)"
    assert re.search(rf"^Failed   <<< my_node \[[\d.]+s, {re.escape(failed)}\]$", tested.stdout, re.M), tested.stdout
    assert re.search(rf"^Finished <<< my_tools \[[\d.]+s\]\t\[ no tests ran: {re.escape(skipped)} \]$",
                     tested.stdout, re.M), tested.stdout

    results = roc("work", "test-result", "--all", cwd=workspace)
    assert "".join(f"  {reason}\n" for reason in reasons) in results.stdout
    assert f"build/my_tools/pytest.xml: 1 test, 0 errors, 0 failures, 1 skipped\n  {skipped}\n" in results.stdout
    data = json.loads(roc("work", "test-result", "--format", "json", cwd=workspace).stdout)
    assert [(r["path"], r["not_started"]) for r in data["results"]] == [("build/my_node/pytest.xml", reasons)]
    events = [json.loads(line) for line in (workspace / "log" / "latest_test" / "events.log").read_text().splitlines()]
    assert {e["task"]: e["reason"] for e in events if e["event"] in ("TaskFailed", "TestsNotRun")} == {
        "my_node": failed, "my_tools": skipped}
