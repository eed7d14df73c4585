"""What every ``roc launch`` run shares while its system runs, whoever starts the processes (the launch
library for a launch file, roc's supervisor for a roc.toml system): the orphan guard, the run's log
directory, the output (plain lines or the live view), the process table, the signals that stop it, and
the ``--check`` report."""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from roc.errors import EXIT_INTERRUPTED
from roc.launch.check import CheckOptions
from roc.launch.guard import Guard
from roc.launch.monitor import Monitor
from roc.launch.view import LiveView, PlainOutput
from roc.middleware import process_environment

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


@dataclass
class RunOptions:
    title: str  # what is launched, for the live view
    log_base: Path | None  # None: no logs
    view: bool  # the live status view (a terminal)
    check: CheckOptions | None = None
    warm_start: bool = True  # fork Python processes from a warm interpreter (roc/launch/warm_start.py)
    ros_log_layout: bool = False  # a run directory in log_base named as ros2 launch's (outside a workspace)


class Running:
    def __init__(self, options: RunOptions, echo: bool):
        self.options = options
        self.check_file = None
        if options.check is not None:
            from roc.launch.check import load

            self.check_file = load(options.check.path)  # a bad file is reported before anything starts
        self.log_directory: Path | None = None
        if options.log_base is not None and options.ros_log_layout:
            from roc.launch.logs import new_ros_run_directory

            self.log_directory = new_ros_run_directory(options.log_base.absolute())
        elif options.log_base is not None:
            from roc.handlers.logs import new_log_directory

            self.log_directory = new_log_directory(options.log_base.absolute(), "launch")
        self.guard = Guard()
        plain = PlainOutput()
        self.monitor = Monitor(plain, self.log_directory, echo)
        self.output: LiveView | PlainOutput = LiveView(self.monitor.snapshot, options.title) if options.view else plain
        self.monitor.output = self.output
        self.stopping = self.monitor.stopping  # set by the first signal, or when the run ends
        self.check_passed: bool | None = None  # None: not checked (yet)
        self.killed = False  # a second signal killed every process
        self._check_thread: threading.Thread | None = None
        self._previous: dict[int, object] = {}

    def environment(self, extra: dict[str, str] | None = None) -> dict[str, str]:
        """The environment of every process the run starts: roc's, with the guard's token and the middleware
        RMW_IMPLEMENTATION names (roc.middleware)."""
        return self.guard.environment(process_environment({**os.environ, **(extra or {})}))

    def catch_signals(self, stop: Callable[[], None]) -> None:
        """SIGINT, SIGTERM and SIGHUP (a closed terminal) call ``stop`` once; a second one stops every
        process of the run at once (SIGKILL)."""

        def on_signal(signum: int, _frame) -> None:
            if self.stopping.is_set():
                self.monitor.note(f"[WARNING] [roc]: {signal.Signals(signum).name} again, killing every process now")
                self.killed = True
                self.guard.close(grace=0.0)
                return
            self.stopping.set()
            stop()

        self._previous = {signum: signal.signal(signum, on_signal) for signum in STOP_SIGNALS}

    def start_check(self, ready: threading.Event, request_stop: Callable[[], None]) -> None:
        """Once ``ready`` is set, probe the ``--check`` expectations; with ``--exit-after-check``, then
        ``request_stop``."""
        if self.check_file is None or self.options.check is None:
            return
        checks, options = self.check_file, self.options.check

        def check() -> None:
            from roc.launch.check import run_checks

            ready.wait()
            if self.stopping.is_set():
                return
            try:
                self.check_passed = run_checks(checks, options, self.output,  # type: ignore[arg-type]
                                               self.stopping.is_set)
            except Exception as error:  # noqa: BLE001 - a check that cannot run is a failed check, not a crash
                self.monitor.note(f"[ERROR] [roc]: --check {options.path}: {error}")
                self.check_passed = False
            if options.exit_after and not self.stopping.is_set():
                self.monitor.note(f"[INFO] [roc]: --exit-after-check: "
                                  f"{'every expectation holds' if self.check_passed else 'expectations failed'}, "
                                  "stopping")
                self.stopping.set()
                request_stop()

        self._check_thread = threading.Thread(target=check, name="roc-check", daemon=True)
        self._check_thread.start()

    def exit_code(self, code: int) -> int:
        """130 when a second signal killed the run; with ``--exit-after-check``, the check decides (1 when
        it failed or never ran); 1 for a code that is a signal."""
        if self.killed:
            return EXIT_INTERRUPTED
        if code < 0:
            return 1
        if self.options.check is not None and self.options.check.exit_after:
            return 0 if self.check_passed and code == 0 else 1
        return code

    def close(self) -> None:
        """Stop whatever is left of the run (and say so), end the output, close the logs."""
        left = self.guard.close()
        if left:
            self.monitor.note(f"[WARNING] [roc]: stopped {len(left)} processes left behind: "
                              f"{', '.join(map(str, left))}")
        if self._check_thread is not None:
            self._check_thread.join(timeout=1.0)
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)  # type: ignore[arg-type]
        self.output.close()
        self.monitor.close()
        sys.stdout.flush()
