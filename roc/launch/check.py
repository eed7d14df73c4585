"""``roc launch --check FILE``: once the system has started, the expectations of ``roc graph check``
(roc/check/) probed against it, as probe tasks of roc's engine, each probed again until it holds or the
file's ``timeout`` has passed (a system that is coming up). The report is graph check's."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from roc.check.expectations import CheckFile
from roc.errors import UsageError


@dataclass
class CheckOptions:
    path: Path
    exit_after: bool = False  # stop the system once reported; exit 0 only when every probe passed
    use_daemon: bool = True
    spin_time: float | None = None


def load(path: Path) -> CheckFile:
    from roc.check.expectations import load_checks

    checks = load_checks(path)
    if not checks.expectations:
        raise UsageError(f"{path}: the [check] table expects nothing; add nodes or [[check.topic]] tables")
    return checks


def run_checks(checks: CheckFile, options: CheckOptions, stream: TextIO, stopped: Callable[[], bool]) -> bool:
    """Probe every expectation (all at once, each until it passes or the timeout); whether all passed."""
    from roc.check.probes import KIND, probe_console, probe_task
    from roc.engine.executor import execute
    from roc.ros.client import Session

    session = Session(use_daemon=options.use_daemon, spin_time=options.spin_time, long_lived=True)
    try:
        tasks = [probe_task(e, session, checks.timeout, checks.rate_window, wait=checks.timeout, stopped=stopped)
                 for e in checks.expectations]
        return execute(tasks, probe_console(stream), workers=0, continue_on_error=True, kind=KIND).ok
    finally:
        session.close()
