"""The suite's own rules for oracles (tests/helpers/oracles.py, tests/conftest.py): tests whose oracle is
missing are skipped and summed up at the end of the run, one line per reason; in CI they fail instead."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.build import REPO

PROBE_TESTS = '''
import pytest
from helpers.oracles import SHARED, require_oracle

@pytest.mark.parametrize("n", range(3))
def test_needs_the_cli(n):
    require_oracle("ros2 CLI", SHARED / "oracles" / "cli.sh")

@pytest.fixture(scope="module")
def reference():
    return require_oracle("reference", SHARED / "reference")

def test_needs_a_reference(reference):
    pass

def test_needs_nothing():
    pass
'''


def _run_probe_suite(tmp_path: Path, shared: Path, workers: int = 0, **extra: str) -> subprocess.CompletedProcess:
    """pytest (on ``workers`` pytest-xdist workers, as scripts/test.sh runs it) on a tiny suite with
    tests/conftest.py and the helpers it loads, the oracles looked up in ``shared``."""
    suite = tmp_path / "suite"
    (suite / "helpers").mkdir(parents=True)
    for name in ("conftest.py", "helpers/__init__.py", "helpers/oracles.py", "helpers/build.py", "helpers/cpp.py",
                 "helpers/rmw.py"):
        shutil.copy(REPO / "tests" / name, suite / name)
    (suite / "test_probe.py").write_text(PROBE_TESTS)
    env = {k: v for k, v in os.environ.items() if k not in ("CI", "PYTEST_ADDOPTS")}
    env.update(ROC_TEST_SHARED=str(shared), **extra)
    command = [sys.executable, "-m", "pytest", "-n", str(workers), "-p", "no:cacheprovider", "-q", str(suite)]
    return subprocess.run(command, cwd=suite, env=env, capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("workers", [0, pytest.param(2, marks=pytest.mark.slow)])
def test_skips_for_missing_oracles_are_summed_up_one_line_per_reason(tmp_path: Path, workers: int) -> None:
    missing = tmp_path / "no-shared"
    run = _run_probe_suite(tmp_path, missing, workers)
    assert run.returncode == 0, run.stdout + run.stderr
    summary = run.stdout.split("missing oracles")[1].splitlines()[1:3]
    assert summary == [f"3 tests skipped: oracle ros2 CLI not found at {missing}/oracles/cli.sh",
                       f"1 test skipped: oracle reference not found at {missing}/reference"]
    assert "1 passed, 4 skipped" in run.stdout


def test_in_ci_a_missing_oracle_fails_the_run(tmp_path: Path) -> None:
    run = _run_probe_suite(tmp_path, tmp_path / "no-shared", CI="true")
    assert run.returncode == 1
    assert "3 failed, 1 passed, 1 error" in run.stdout and "missing oracles" not in run.stdout
    assert "CI must have every oracle" in run.stdout


def test_with_the_oracles_nothing_is_skipped(tmp_path: Path) -> None:
    shared = tmp_path / "shared"
    (shared / "oracles").mkdir(parents=True)
    (shared / "oracles" / "cli.sh").write_text("")
    (shared / "reference").mkdir()
    run = _run_probe_suite(tmp_path, shared, CI="true")
    assert run.returncode == 0 and "5 passed" in run.stdout, run.stdout
