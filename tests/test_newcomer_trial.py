"""Fixes of issue 33 (what a newcomer trial of the whole tool found) that need no ROS graph: the
set-up's system changes are opt-in, the oracles' skips are summarised, exit codes and hints, and the
messages of clean, param set and the dependency check."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

from build_helpers import REPO

# ---- scripts/setup.sh changes the system only when asked -----------------------------------------

# what the set-up runs, without zsh and fish
TOOLS = ("bash", "dirname", "sha256sum", "cut", "cat", "flock", "grep", "env", "rm")


def _setup_without_shells(tmp_path: Path, **extra: str) -> tuple[subprocess.CompletedProcess, str]:
    """Run a copy of scripts/setup.sh all through (ROC_SETUP_FORCE=1) as root, on a PATH without zsh and
    fish, in a checkout whose venv's Python does nothing, with an apt-get that records its arguments;
    returns the run and what apt-get was asked."""
    checkout = tmp_path / "checkout"
    (checkout / "scripts").mkdir(parents=True)
    shutil.copy(REPO / "scripts" / "setup.sh", checkout / "scripts")
    fake = tmp_path / "bin"
    fake.mkdir()
    for tool in TOOLS:
        os.symlink(shutil.which(tool), fake / tool)
    calls = tmp_path / "apt-get.calls"
    scripts = {fake / "apt-get": f'echo "$*" >> {calls}', fake / "id": "echo 0"}
    scripts.update({checkout / ".venv" / "bin" / name: "exit 0" for name in ("python", "roc", "colcon")})
    for path, body in scripts.items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(f"#!/bin/sh\n{body}\n")
        path.chmod(0o755)
    env = {"PATH": str(fake), "HOME": str(tmp_path), "TMPDIR": str(tmp_path), "ROC_SETUP_FORCE": "1", **extra}
    run = subprocess.run(["bash", str(checkout / "scripts" / "setup.sh")], env=env, capture_output=True, text=True,
                         timeout=120)
    return run, calls.read_text() if calls.exists() else ""


def test_the_set_up_installs_no_system_package_unless_asked(tmp_path: Path) -> None:
    run, asked = _setup_without_shells(tmp_path)
    assert run.returncode == 0, run.stderr
    assert asked == ""
    assert "setup: zsh fish not installed: their tests will be skipped (ROC_SETUP_SHELLS=1 installs them)" in run.stderr


def test_roc_setup_shells_installs_zsh_and_fish_and_says_so(tmp_path: Path) -> None:
    run, asked = _setup_without_shells(tmp_path, ROC_SETUP_SHELLS="1")
    assert run.returncode == 0, run.stderr
    assert "setup: ROC_SETUP_SHELLS=1: installing zsh fish with apt-get" in run.stderr
    assert asked.splitlines() == ["update -qq", "install -y -qq zsh fish"]


def test_ci_opts_in_and_the_set_up_says_what_the_option_does() -> None:
    assert "export ROC_SETUP_SHELLS=1" in (REPO / ".ci" / "run").read_text()
    header = (REPO / "scripts" / "setup.sh").read_text().split("set -euo pipefail")[0]
    assert "ROC_SETUP_SHELLS=1  also install zsh and fish" in header


# ---- tests skipped for a missing oracle are summed up; CI fails instead ------------------------------

PROBE_TESTS = '''
import pytest
from oracles import SHARED, require_oracle

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


def _run_probe_suite(tmp_path: Path, shared: Path, **extra: str) -> subprocess.CompletedProcess:
    """pytest (two workers) on a tiny suite with tests/conftest.py and tests/oracles.py, the oracles
    looked up in ``shared``."""
    suite = tmp_path / "suite"
    suite.mkdir()
    for name in ("conftest.py", "oracles.py"):
        shutil.copy(REPO / "tests" / name, suite)
    (suite / "test_probe.py").write_text(PROBE_TESTS)
    env = {k: v for k, v in os.environ.items() if k not in ("CI", "PYTEST_ADDOPTS")}
    env.update(ROC_TEST_SHARED=str(shared), **extra)
    return subprocess.run([sys.executable, "-m", "pytest", "-n", "2", "-p", "no:cacheprovider", "-q", str(suite)],
                          cwd=suite, env=env, capture_output=True, text=True, timeout=120)


def test_skips_for_missing_oracles_are_summed_up_one_line_per_reason(tmp_path: Path) -> None:
    missing = tmp_path / "no-shared"
    run = _run_probe_suite(tmp_path, missing)
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
