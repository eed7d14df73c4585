"""Fast checks of ``roc work test``'s pieces: colcon's pytest arguments, cached-result keys, selection by
the last test result."""

from __future__ import annotations

import argparse
from pathlib import Path

from helpers.build import copy_fixture, roc

from roc.cli.options import add_selection_arguments
from roc.engine.events import (
    TaskAborted,
    TaskFailed,
    TaskFinished,
    TestFailures,
)
from roc.handlers.logs import ResultStore
from roc.testing.cache import (
    read_test_state,
    rerun_reasons,
    results_key,
    results_parts,
    write_test_state,
)
from roc.testing.plan import PackageTest
from roc.testing.runner import TestOptions, pytest_addopts
from roc.workspace.package import Package
from roc.workspace.selection import select_packages


def test_pytest_arguments_are_colcons(tmp_path: Path) -> None:
    options = TestOptions(build_base=Path("/ws/build"), install_base=Path("/ws/install"),
                          pytest_args=("-k", "double"), retest_until_pass=2)
    args, env = pytest_addopts("pkg", Path("/ws/src/pkg"), options)
    assert args == ["--tb=short", "--junit-xml=/ws/build/pkg/pytest.xml", "--junit-prefix=pkg",
                    "-o", "cache_dir=/ws/build/pkg/.pytest_cache", "--reruns=2", "-k", "double"]
    assert env == {}
    results = TestOptions(build_base=Path("/ws/build"), install_base=Path("/ws/install"),
                          test_result_base=Path("/ws/results"), pytest_with_coverage=True)
    args, env = pytest_addopts("pkg", Path("/ws/src/pkg"), results)
    assert args[1] == "--junit-xml=/ws/results/pkg/pytest.xml"
    assert args[5:] == ["--cov=/ws/src/pkg", "--cov-report=html:/ws/build/pkg/coverage.html",
                        "--cov-report=xml:/ws/build/pkg/coverage.xml", "--cov-branch"]
    assert env == {"COVERAGE_FILE": "/ws/build/pkg/.coverage"}


def test_cached_result_needs_the_same_key_a_pass_and_the_result_files(tmp_path: Path) -> None:
    source, build = tmp_path / "src" / "pkg", tmp_path / "build"
    source.mkdir(parents=True)
    (source / "test_it.py").write_text("def test_ok(): pass\n")
    (build / "pkg").mkdir(parents=True)
    assert results_key(source, build, "pkg", [], {}, {})[0] is None  # not built by roc: never cached
    assert rerun_reasons({}, results_parts(source, build, "pkg", [], {}, {})[0]) == ["not built by roc"]
    (build / "pkg" / "roc_state.json").write_text('{"fingerprint": "f1", "files": {}}')
    (build / "dep").mkdir()
    (build / "dep" / "roc_state.json").write_text('{"fingerprint": "d1", "files": {}}')

    def reasons(options: dict | None = None) -> list[str]:
        state = read_test_state(build / "pkg")
        return rerun_reasons(state, results_parts(source, build, "pkg", ["dep"], options or {}, state)[0])

    assert reasons() == ["never tested"]
    parts, files = results_parts(source, build, "pkg", ["dep"], {}, {})
    key, _ = results_key(source, build, "pkg", ["dep"], {}, {})
    write_test_state(build / "pkg", key, False, files, [], parts)
    assert reasons() == ["failed last time"]
    result = build / "pkg" / "pytest.xml"
    result.write_text("<testsuite tests='1' failures='0'/>")
    write_test_state(build / "pkg", key, True, files, [str(result)], parts)
    assert reasons() == []
    assert reasons({"pytest": ["-x"]}) == ["option changed: pytest"]
    (source / "test_it.py").write_text("def test_ok(): assert True\n")
    (source / "test_new.py").write_text("")
    assert reasons() == ["files added: test_new.py", "files changed: test_it.py"]
    (source / "test_new.py").unlink()
    (source / "test_it.py").write_text("def test_ok(): pass\n")
    assert reasons() == []
    (build / "pkg" / "roc_state.json").write_text('{"fingerprint": "f2", "files": {}}')
    assert reasons() == ["build changed"]
    (build / "pkg" / "roc_state.json").write_text('{"fingerprint": "f1", "files": {}}')
    (build / "dep" / "roc_state.json").write_text('{"fingerprint": "d2", "files": {}}')
    assert reasons() == ["dependency changed: dep"]
    (build / "dep" / "roc_state.json").write_text('{"fingerprint": "d1", "files": {}}')
    result.unlink()
    assert reasons() == ["result files missing"]


def test_the_check_runs_at_dispatch_and_says_why(tmp_path: Path) -> None:
    """A test task's check reads the state when it is called (not when the task is planned)."""
    source, build = tmp_path / "src" / "pkg", tmp_path / "build"
    source.mkdir(parents=True)
    (source / "test_it.py").write_text("def test_ok(): pass\n")
    (build / "pkg").mkdir(parents=True)
    package = Package(name="pkg", path=Path("src", "pkg"), type="ros.ament_python", dependencies={})
    options = TestOptions(build_base=build, install_base=tmp_path / "install")
    test = PackageTest(package, source, [], options)
    assert test.check() == ["not built by roc"]
    (build / "pkg" / "roc_state.json").write_text('{"fingerprint": "f1", "files": {}}')  # built since
    assert test.check() == ["never tested"]
    write_test_state(build / "pkg", "some key", True, test.files, [], test.parts)
    assert test.check() == ["test inputs changed"]
    write_test_state(build / "pkg", results_key(source, build, "pkg", [], options.digest(), {})[0], True,
                     test.files, [], test.parts)
    assert test.check() == []
    assert PackageTest(package, source, [], options, force=True).check() == ["--force"]
    assert PackageTest(package, source, [], options, use_cache=False).check() == ["--no-cache"]


def test_selection_by_the_last_test_result(tmp_path: Path) -> None:
    packages = [Package(name=name, path=Path("src", name), type="ros.ament_cmake", dependencies={})
                for name in ("failed", "passed", "aborted", "untested")]
    for name, text in (("failed", "test failures\n"), ("passed", "0\n"), ("aborted", "SIGINT\n")):
        (tmp_path / name).mkdir()
        (tmp_path / name / "colcon_test.rc").write_text(text)
    parser = argparse.ArgumentParser()
    add_selection_arguments(parser)
    failures = parser.parse_args(["--packages-select-test-failures"])
    assert select_packages(failures, packages, tmp_path) == {"failed"}
    not_passed = parser.parse_args(["--packages-skip-test-passed"])
    assert select_packages(not_passed, packages, tmp_path) == {"failed", "aborted", "untested"}


def test_build_and_list_select_by_the_last_test_result_as_colcon(tmp_path: Path) -> None:
    """colcon-test-result gives every verb these options (they used to be refused with "roc has no test
    verb yet")."""
    workspace = copy_fixture("selection", tmp_path / "ws")
    for name, text in (("core", "test failures\n"), ("tool", "0\n")):
        (workspace / "build" / name).mkdir(parents=True)
        (workspace / "build" / name / "colcon_test.rc").write_text(text)
    failures = roc("work", "list", "-n", "--packages-select-test-failures", cwd=workspace)
    assert (failures.returncode, failures.stdout, failures.stderr) == (0, "core\n", "")
    not_passed = roc("work", "list", "-n", "--packages-skip-test-passed", cwd=workspace)
    assert not_passed.returncode == 0 and "tool" not in not_passed.stdout.split() and "core" in not_passed.stdout
    explained = roc("work", "build", "--packages-select-test-failures", "--explain", cwd=workspace)
    assert (explained.returncode, explained.stdout) == (0, "core: never built\n"), explained.stderr


def test_result_store_writes_colcons_test_results(tmp_path: Path) -> None:
    store = ResultStore(tmp_path)
    for event in (TaskFinished("passed", "test"), TestFailures("failing", "test"), TaskFinished("failing", "test"),
                  TaskFailed("error", "test"), TaskAborted("stopped", "test"), TaskFinished("built"),
                  TaskFinished("generated", "idl")):
        store(event)
    assert {p.relative_to(tmp_path).as_posix(): p.read_text() for p in tmp_path.glob("*/*")} == {
        "passed/colcon_test.rc": "0\n", "failing/colcon_test.rc": "test failures\n",
        "error/colcon_test.rc": "1\n", "stopped/colcon_test.rc": "SIGINT\n", "built/colcon_build.rc": "0\n"}


def test_result_store_fails_the_build_of_a_package_whose_idl_task_failed(tmp_path: Path) -> None:
    store = ResultStore(tmp_path, kind="build")
    for event in (TaskFinished("ok", "idl"), TaskFailed("broken", "idl"), TaskAborted("stopped", "idl")):
        store(event)
    assert {p.relative_to(tmp_path).as_posix(): p.read_text() for p in tmp_path.glob("*/*")} == {
        "broken/colcon_build.rc": "1\n", "stopped/colcon_build.rc": "SIGINT\n"}
