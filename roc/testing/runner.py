"""How one package is tested, as colcon tests it: CTest in the build directory of CMake and ament_cmake
packages, pytest in the source directory of Python packages, in the environment of the package's
installed dependencies and its own install prefix."""

from __future__ import annotations

import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from roc.engine.events import TestFailures, TestsNotRun
from roc.engine.process import TaskContext, TaskError
from roc.testing.results import not_started

CTEST_TESTS_FAILED = 8
PYTEST_TESTS_FAILED = 1
PYTEST_NO_TESTS = 5
CMAKE_TYPES = ("ros.ament_cmake", "ros.cmake", "cmake")
PYTHON_TYPES = ("ros.ament_python", "python")


@dataclass(frozen=True)
class TestOptions:
    """The ``roc work test`` options that shape how packages are tested."""

    __test__ = False

    build_base: Path
    install_base: Path
    merge_install: bool = False
    test_result_base: Path | None = None
    ctest_args: tuple[str, ...] = ()
    pytest_args: tuple[str, ...] | None = None
    pytest_with_coverage: bool = False
    retest_until_fail: int = 0
    retest_until_pass: int = 0

    def result_dir(self, name: str) -> Path:
        return (self.test_result_base or self.build_base) / name

    def digest(self) -> dict:
        """What changes the outcome of a test run (for cached results)."""
        return {"ctest": list(self.ctest_args), "pytest": list(self.pytest_args or ()),
                "coverage": self.pytest_with_coverage, "until_fail": self.retest_until_fail,
                "until_pass": self.retest_until_pass, "results": str(self.test_result_base or "")}


def testable(package_type: str) -> bool:
    return package_type in CMAKE_TYPES + PYTHON_TYPES


def run_package_tests(context: TaskContext, package_type: str, name: str, source: Path, env: dict[str, str],
                 options: TestOptions) -> bool:
    """Run the package's tests; True when all passed (or there were none)."""
    if package_type in CMAKE_TYPES:
        return _ctest(context, name, env, options)
    return _pytest(context, name, source, env, options)


def _cmake_cache_value(build_dir: Path, key: str) -> str | None:
    try:
        lines = (build_dir / "CMakeCache.txt").read_text(errors="replace").splitlines()
    except OSError:
        return None
    prefix = f"{key}:"
    for line in lines:
        if line.startswith(prefix) and "=" in line:
            return line.split("=", 1)[1]
    return None


def _has_ctests(build_dir: Path, ctest: str, env: dict[str, str]) -> bool:
    """Whether ``ctest --show-only`` lists a test (an indented line), as colcon checks."""
    listing = subprocess.run([ctest, "--show-only"], cwd=build_dir, env=env, capture_output=True, text=True,
                             stdin=subprocess.DEVNULL)
    return any(line.startswith("  ") for line in listing.stdout.splitlines())


def _ctest(context: TaskContext, name: str, env: dict[str, str], options: TestOptions) -> bool:
    build_dir = options.build_base / name
    if not (build_dir / "CMakeCache.txt").is_file():
        raise TaskError(f"'{build_dir}' has no CMake build; build the package first (roc work build)")
    ctest = shutil.which("ctest", path=env.get("PATH")) or shutil.which("ctest")
    if ctest is None:
        raise TaskError("cannot find 'ctest' on PATH")
    if not _has_ctests(build_dir, ctest, env):
        return True
    args = ["-D", "ExperimentalTest", "--no-compress-output", "-V", "--force-new-ctest-process",
            *options.ctest_args]
    if "-C" not in args and "--build-config" not in args:
        build_type = _cmake_cache_value(build_dir, "CMAKE_BUILD_TYPE")
        args[0:0] = ["-C", build_type if build_type in ("Debug", "MinSizeRel", "RelWithDebInfo") else "Release"]
    if options.retest_until_fail:
        args += ["--repeat-until-fail", str(options.retest_until_fail + 1)]
    tag_file = build_dir / "Testing" / "TAG"
    tag_file.unlink(missing_ok=True)  # a new run gets a new tag directory
    passed = True
    for attempt in range(options.retest_until_pass + 1):
        returncode = context.run([ctest, *args], cwd=str(build_dir), env=env)
        if returncode == 0:
            passed = True
            break
        if returncode != CTEST_TESTS_FAILED:
            raise TaskError(f"ctest exited with code {returncode}")
        passed = False
        if attempt == 0:
            args.append("--rerun-failed")
    if not passed:
        context.emit(TestFailures(context.name, context.kind))
    _copy_ctest_results(tag_file, options.result_dir(name))
    return passed


def _copy_ctest_results(tag_file: Path, destination: Path) -> None:
    """With --test-result-base, CTest's TAG and latest Test.xml are copied there (as colcon does)."""
    if destination == tag_file.parent.parent or not tag_file.is_file():
        return
    lines = tag_file.read_text().splitlines()
    latest = tag_file.parent / (lines[0] if lines else "") / "Test.xml"
    if not lines or not latest.is_file():
        return
    target = destination / "Testing" / lines[0]
    target.mkdir(parents=True, exist_ok=True)
    shutil.copy2(tag_file, destination / "Testing" / "TAG")
    shutil.copy2(latest, target / "Test.xml")


def _posix(path: Path) -> str:
    return str(PurePosixPath(*path.parts))


def _plugin(package: str, module: str, option: str) -> bool:
    """Whether the pytest plugin an option needs is installed (else the option is ignored, as in colcon)."""
    import importlib.util

    from roc.messages import warn

    if importlib.util.find_spec(module) is None:
        warn(f"ignored {option} for '{package}': the pytest plugin '{module}' is not installed")
        return False
    return True


def pytest_addopts(name: str, source: Path, options: TestOptions) -> tuple[list[str], dict[str, str]]:
    """colcon's pytest arguments (passed in PYTEST_ADDOPTS) and extra environment."""
    build_dir = options.build_base / name
    args = ["--tb=short", f"--junit-xml={_posix(options.result_dir(name) / 'pytest.xml')}", f"--junit-prefix={name}",
            "-o", f"cache_dir={_posix(build_dir / '.pytest_cache')}"]
    env: dict[str, str] = {}
    if options.pytest_with_coverage:
        args += [f"--cov={_posix(source)}", f"--cov-report=html:{_posix(build_dir / 'coverage.html')}",
                 f"--cov-report=xml:{_posix(build_dir / 'coverage.xml')}", "--cov-branch"]
        env["COVERAGE_FILE"] = str(build_dir / ".coverage")
    if options.retest_until_fail and _plugin(name, "pytest_repeat", "--retest-until-fail"):
        args.append(f"--count={options.retest_until_fail + 1}")
    if options.retest_until_pass and _plugin(name, "pytest_rerunfailures", "--retest-until-pass"):
        args.append(f"--reruns={options.retest_until_pass}")
    args += options.pytest_args or ()
    return args, env


MISSING_RESULT = """<?xml version="1.0" encoding="UTF-8"?>
<testsuite name="{name}" tests="1" failures="0" time="0" errors="1" skipped="0">
  <testcase classname="{name}" name="pytest.missing_result" time="0">
    <failure message="The test invocation failed without generating a result file{why}."/>
  </testcase>
</testsuite>
"""


def _reasons(reasons: list[str]) -> str:
    """The first reason, and how many more there are."""
    return reasons[0] + (f" (and {len(reasons) - 1} more)" if len(reasons) > 1 else "")


def _pytest(context: TaskContext, name: str, source: Path, env: dict[str, str], options: TestOptions) -> bool:
    args, extra = pytest_addopts(name, source, options)
    env = {**env, **extra, "PYTEST_ADDOPTS": " ".join(a if " " not in a else f'"{a}"' for a in args)}
    env.setdefault("PYTHONDONTWRITEBYTECODE", "1")
    junit = options.result_dir(name) / "pytest.xml"
    junit.parent.mkdir(parents=True, exist_ok=True)
    placeholder = MISSING_RESULT.format(name=name, why="")
    junit.write_text(placeholder)  # replaced by pytest unless it fails early
    returncode = context.run([sys.executable, "-m", "pytest"], cwd=str(source), env=env)
    if returncode == PYTEST_TESTS_FAILED:
        context.emit(TestFailures(context.name, context.kind))
        return False
    if returncode == PYTEST_NO_TESTS:
        reasons = not_started(junit)
        context.emit(TestsNotRun(context.name, context.kind, reason=_reasons(reasons) if reasons else ""))
    elif returncode != 0:
        if junit.read_text() == placeholder:  # no result file: pytest's stderr, shown with the task, says why
            junit.write_text(MISSING_RESULT.format(name=name, why=f" (pytest exited with code {returncode})"))
            raise TaskError(f"pytest exited with code {returncode}")
        # why, where colcon says only "exited with code 2": the test files pytest could not import
        reasons = not_started(junit)
        raise TaskError(f"pytest exited with code {returncode}" + (f": {_reasons(reasons)}" if reasons else ""))
    return True
