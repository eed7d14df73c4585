"""A build running on a thread of its own for the TUI: its TaskBoard (the event handler the build
screen draws), the event that stops it, and its exit code once it ends."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from roc.errors import EXIT_FAILURE, RocError
from roc.handlers.board import TaskBoard

# (handlers, stop) -> exit code: roc.commands.work.build's build, with these event handlers instead of the console
Start = Callable[[list, threading.Event], int]


class BuildRun:
    def __init__(self, start: Start, kind: str = "build") -> None:
        self.board = TaskBoard(kind)
        self.stop = threading.Event()
        self.started = time.monotonic()
        self.code: int | None = None
        self.error: str | None = None  # a build that could not run (a lock held, bad options)
        self._start = start
        self._thread = threading.Thread(target=self._run, name="roc-tui-build", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        try:
            self.code = self._start([self.board], self.stop)
        except RocError as error:
            self.error, self.code = str(error), error.exit_code
        except Exception as error:  # noqa: BLE001 - shown in the TUI rather than lost with the thread
            self.error, self.code = f"internal error: {type(error).__name__}: {error}", EXIT_FAILURE

    def running(self) -> bool:
        return self._thread.is_alive()

    def finish(self) -> int:
        """Stop the build if it still runs (its process trees with it) and wait for its end."""
        self.stop.set()
        self._thread.join()
        return EXIT_FAILURE if self.code is None else self.code
