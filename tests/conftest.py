"""Suite-wide set-up.

- The suite's processes stop on SIGINT (the tests' Ctrl+C) even when the suite was started with SIGINT
  ignored, as a shell does for a command it runs in the background (``bash scripts/test.sh &``): an
  ignored signal stays ignored in every child, a handled one is reset to its default.
- Tests skipped because an oracle is missing (tests/helpers/oracles.py), or the C++ stack or rmw_cyclonedds
  they need is not built (tests/helpers/cpp.py, the tests marked ``cpp``; tests/helpers/rmw.py), are summed up at the end of the run, one line per
  reason, so that a checkout without ``../shared`` or the stack says what it did not test.
- The suite's own process writes byte-code (see below); the processes it starts follow the environment.
- The whole suite runs on Jazzy (.venv). On another distribution (``bash scripts/test.sh --distro
  kilted``: .venv-kilted) only the distribution suite runs, the tests marked ``distro``: each area end to
  end; the others are distribution-independent and run once, on Jazzy. ROC_TEST_UNMARKED=1 runs them too.
"""

import os
import signal
import sys
from collections import Counter

import pytest
from helpers.build import share_compiles
from helpers.cpp import MISSING as MISSING_CPP_STACK
from helpers.rmw import MISSING as MISSING_CYCLONEDDS

from roc import distribution

FULL_SUITE_DISTRO = "jazzy"
DISTRO = distribution.current({}).name  # the venv's (tests/helpers/build.py: DISTRO)

share_compiles()

# pytest keeps the test modules it rewrote (for its assert messages) only where byte-code may be written:
# with PYTHONDONTWRITEBYTECODE set machine-wide, each worker rewrote each changed test module on every run
# (a second or more of the quick loop). The processes the tests start still see the variable.
sys.dont_write_bytecode = False

if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


def _skip_reason(report) -> str:
    longrepr = report.longrepr
    reason = longrepr[2] if isinstance(longrepr, tuple) and len(longrepr) == 3 else str(longrepr)
    return reason.removeprefix("Skipped: ")


def pytest_collection_modifyitems(config, items) -> None:
    if DISTRO == FULL_SUITE_DISTRO or os.environ.get("ROC_TEST_UNMARKED") == "1":
        return
    kept = [item for item in items if item.get_closest_marker("distro")]
    deselected = [item for item in items if not item.get_closest_marker("distro")]
    if deselected:
        config.hook.pytest_deselected(items=deselected)
        items[:] = kept


def pytest_report_header(config) -> str:
    suite = "the whole suite" if DISTRO == FULL_SUITE_DISTRO else "the distribution suite (tests marked distro)"
    return f"ROS 2 {DISTRO}: {suite}"


def pytest_terminal_summary(terminalreporter) -> None:
    reasons = Counter(_skip_reason(r) for r in terminalreporter.stats.get("skipped", []))
    missing = sorted(((reason, count) for reason, count in reasons.items()
                      if reason.startswith(("oracle ", MISSING_CPP_STACK, MISSING_CYCLONEDDS))),
                     key=lambda item: (-item[1], item[0]))  # the most skipped first
    if missing:
        terminalreporter.section("missing oracles and stacks")
        for reason, count in missing:
            terminalreporter.write_line(f"{count} test{'s' if count != 1 else ''} skipped: {reason}")


@pytest.fixture(scope="session")
def launch_demo_prefix(tmp_path_factory):
    """roc_launch_demo (workspaces/fixtures/launch) built by roc once per test worker: its install prefix."""
    from helpers.launch import build_demo

    return build_demo(tmp_path_factory.mktemp("launch_demo"))


@pytest.fixture(scope="session")
def example_workspace(tmp_path_factory):
    """workspaces/example built by roc once per test worker (its tests and the manual's live examples share
    it: mark them ``xdist_group("example_workspace")`` to build it once). Read it, never change it."""
    import shutil

    from helpers.build import REPO, roc

    workspace = tmp_path_factory.mktemp("example")
    shutil.copytree(REPO / "workspaces" / "example" / "src", workspace / "src")
    result = roc("work", "build", "--parallel-workers", "2", cwd=workspace)
    assert result.returncode == 0, result.stdout + result.stderr
    return workspace
