"""roc tui never imports rclpy, its drill-down screens included: the echo pane, a service call and an
action goal with its cancel (the daemon decodes and encodes their messages). The tests of test_tui_screens.py
that drive those screens run in a fresh pytest process, each ending with a check that no rclpy module
was loaded (this process has loaded rclpy from other tests)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.build import REPO

pytestmark = pytest.mark.slow
DRILL_DOWNS = "echo_pause or service_call or action_goal"


def test_the_drill_down_screens_load_no_rclpy() -> None:
    run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:xdist",
                          str(Path(__file__).with_name("test_tui_screens.py")), "-k", DRILL_DOWNS],
                         env={**os.environ, "ROC_TUI_ASSERT_NO_RCLPY": "1"}, cwd=REPO,
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-2000:]
    assert "3 passed" in run.stdout, run.stdout[-2000:]
