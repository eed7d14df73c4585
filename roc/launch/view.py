"""Where a running system's lines go: plain lines when the output is not a terminal (ros2 launch's
format, for logs and CI), or, on a terminal, the same lines scrolling above a live table with one row
per process: name, pid, state, restarts, CPU, memory, uptime and its last line of output (rich)."""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable
from typing import TextIO

from roc.launch.monitor import ProcessRow

REFRESH_SECONDS = 1.0
FLUSH_SECONDS = 0.1  # lines are printed above the table in batches: each print redraws it


class PlainOutput:
    def __init__(self, stream: TextIO | None = None):
        self.stream = stream or sys.stdout
        self._lock = threading.Lock()

    def line(self, text: str) -> None:
        with self._lock:
            try:
                self.stream.write(text + "\n")
                self.stream.flush()
            except (BrokenPipeError, OSError):  # the reader or the terminal went away: keep supervising
                pass

    def write(self, text: str) -> None:
        """Text that may not end a line (relayed as it comes)."""
        with self._lock:
            try:
                self.stream.write(text)
                self.stream.flush()
            except (BrokenPipeError, OSError):
                pass

    def flush(self) -> None:
        pass

    def close(self) -> None:
        pass


def _duration(seconds: float) -> str:
    seconds = int(seconds)
    if seconds < 60:
        return f"{seconds}s"
    if seconds < 3600:
        return f"{seconds // 60}m{seconds % 60:02d}s"
    return f"{seconds // 3600}h{seconds // 60 % 60:02d}m"


def _memory(size: int) -> str:
    for unit in ("B", "KiB", "MiB"):
        if size < 1024:
            return f"{size:.0f} {unit}"
        size //= 1024
    return f"{size:.0f} GiB"


class Usage:
    """CPU (percent of one core since the last look) and resident memory of each process, by pid."""

    def __init__(self) -> None:
        self._processes: dict[int, object] = {}

    def __call__(self, pid: int | None) -> tuple[str, str]:
        import psutil

        if pid is None:
            return "", ""
        try:
            process = self._processes.get(pid)
            if process is None:
                process = self._processes[pid] = psutil.Process(pid)
                process.cpu_percent()  # the first call starts the measurement
            with process.oneshot():  # type: ignore[attr-defined]
                return (f"{process.cpu_percent():.0f}%",  # type: ignore[attr-defined]
                        _memory(process.memory_info().rss))  # type: ignore[attr-defined]
        except psutil.Error:
            self._processes.pop(pid, None)
            return "", ""


STATE_STYLES = {"running": "green", "waiting": "yellow", "failed": "bold red", "exited": "dim", "stopped": "dim"}


class LiveView:
    """The live table at the bottom of the terminal; ``line`` prints above it."""

    def __init__(self, rows: Callable[[], list[ProcessRow]], title: str):
        from rich.console import Console
        from rich.live import Live

        self.rows, self.title = rows, title
        self.usage = Usage()
        self.console = Console(file=sys.stdout, highlight=False)
        self._pending: list[str] = []
        self._partial = ""  # relayed text after its last newline
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self.live = Live(self, console=self.console, refresh_per_second=1 / REFRESH_SECONDS,
                         redirect_stdout=False, redirect_stderr=False)
        self.live.start()
        self._flusher = threading.Thread(target=self._flush_loop, name="roc-view", daemon=True)
        self._flusher.start()

    def line(self, text: str) -> None:
        with self._lock:
            self._pending.append(text)

    def write(self, text: str) -> None:
        """Relayed text: whole lines are printed, a partial one waits for its end."""
        with self._lock:
            *lines, self._partial = (self._partial + text).split("\n")
            self._pending.extend(lines)

    def flush(self) -> None:
        pass  # lines are printed by the flusher thread

    def _flush(self, everything: bool = False) -> None:
        with self._lock:
            lines, self._pending = self._pending, []
            if everything and self._partial:
                lines.append(self._partial)
                self._partial = ""
        if lines:
            from rich.text import Text

            self.console.print(Text("\n".join(lines)), soft_wrap=True)

    def _flush_loop(self) -> None:
        while not self._stop.wait(FLUSH_SECONDS):
            try:
                self._flush()
            except OSError:  # the terminal went away
                return

    def __rich__(self):
        from rich.table import Table
        from rich.text import Text

        table = Table(title=self.title, title_justify="left", expand=True, box=None, show_edge=False,
                      header_style="bold")
        for column, kwargs in (("process", {"no_wrap": True}), ("pid", {"justify": "right"}), ("state", {}),
                               ("restarts", {"justify": "right"}), ("cpu", {"justify": "right"}),
                               ("memory", {"justify": "right"}), ("uptime", {"justify": "right"}),
                               ("last line", {"ratio": 1, "no_wrap": True, "overflow": "ellipsis"})):
            table.add_column(column, **kwargs)
        now = time.monotonic()
        for row in self.rows():
            running = row.state == "running"
            cpu, memory = ("", "")
            if running and row.host:  # its host reports it; a local PID of that number is another process
                cpu, memory = (f"{row.cpu:.0f}%", _memory(row.rss or 0)) if row.cpu is not None else ("", "")
            elif running:
                cpu, memory = self.usage(row.pid)
            state = row.state + (f" ({row.detail})" if row.detail else "")
            cells = (row.shown, str(row.pid or ""), state, str(row.restarts), cpu, memory,
                     _duration(now - row.started_at) if running else "", row.last_line)
            table.add_row(*(Text(cell, style=STATE_STYLES.get(row.state, "") if index == 2 else "")
                            for index, cell in enumerate(cells)))
        return table

    def close(self) -> None:
        self._stop.set()
        self._flusher.join()
        try:
            self._flush(everything=True)
            self.live.stop()
        except OSError:
            pass
