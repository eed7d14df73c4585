"""What roc knows of the processes of a running system: one row per process (pid, state, restarts, start
time, last line of output), fed by the launch runner's events or by roc's own supervisor, and passed on
to the per-process logs and the output (plain lines or the live view).

Thread-safe: events come from the threads that read the processes' output.
"""

from __future__ import annotations

import re
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

from roc.launch.logs import ProcessLogs

# the time stamp of a ROS log line, "[INFO] [1795613360.189655492] [talker]: ...", left out of the view
ROS_STAMP = re.compile(r"^(\[[A-Z]+\] )\[\d+\.\d+\] ")


class Output(Protocol):
    def line(self, text: str) -> None: ...


@dataclass
class ProcessRow:
    name: str
    pid: int | None = None
    state: str = "waiting"  # waiting, running, exited, failed, stopped
    detail: str = ""  # what it waits for; how it ended
    starts: int = 0
    started_at: float = 0.0  # time.monotonic() of the last start
    last_line: str = ""
    code: int | None = None
    host: str = ""  # the SSH destination of a process on another host; "" for this one
    cpu: float | None = None  # a remote process's usage, as its host reports it (percent of a core)
    rss: int | None = None  # bytes

    @property
    def restarts(self) -> int:
        return max(0, self.starts - 1)

    @property
    def shown(self) -> str:
        """Its name in output lines and the live view: ``HOST:NAME`` for a process on another host."""
        return f"{self.host}:{self.name}" if self.host else self.name


@dataclass
class Monitor:
    """``echo``: print each event as ros2 launch does (roc's own supervisor); off when the launch
    library prints them itself."""

    output: Output
    log_directory: Path | None = None
    echo: bool = True
    rows: dict[str, ProcessRow] = field(default_factory=dict)
    stopping: threading.Event = field(default_factory=threading.Event)  # set: the run is ending, exits are stops
    last_start: float = 0.0  # time.monotonic() of the last process start
    stop_asked: set[str] = field(default_factory=set)  # processes stopped on request (roc tui): an exit is a stop

    def __post_init__(self) -> None:
        self._lock = threading.Lock()
        self.logs = ProcessLogs(self.log_directory) if self.log_directory else None
        self._partial: dict[str, str] = {}

    def _row(self, name: str) -> ProcessRow:
        return self.rows.setdefault(name, ProcessRow(name))

    def snapshot(self) -> list[ProcessRow]:
        with self._lock:
            return [ProcessRow(**vars(row)) for row in self.rows.values()]

    def note(self, text: str) -> None:
        """A line of roc's own."""
        self.output.line(text)

    def place(self, name: str, host: str) -> None:
        """The process runs on another host (shown in its lines and row)."""
        with self._lock:
            self._row(name).host = host

    def shown(self, name: str) -> str:
        row = self.rows.get(name)
        return row.shown if row else name

    def waiting(self, name: str, reason: str) -> None:
        with self._lock:
            row = self._row(name)
            row.state, row.detail = "waiting", reason
        if self.echo:
            self.output.line(f"[INFO] [{self.shown(name)}]: waiting for {reason}")

    def usage(self, name: str, cpu: float, rss: int) -> None:
        """A remote process's CPU and memory, reported by its host."""
        with self._lock:
            row = self._row(name)
            row.cpu, row.rss = cpu, rss

    def started(self, name: str, pid: int, command: list[str], warm: bool = False) -> None:
        with self._lock:
            row = self._row(name)
            row.pid, row.state, row.detail, row.code, row.cpu, row.rss = pid, "running", "", None, None, None
            row.starts += 1
            self.stop_asked.discard(name)
            row.started_at = self.last_start = time.monotonic()
            if self.logs:
                how = " (warm start)" if warm else ""
                self.logs.note(name, f"process started with pid [{pid}]{how}: {' '.join(command)}")
        if self.echo:
            self.output.line(f"[INFO] [{self.shown(name)}]: process started with pid [{pid}]")

    def output_text(self, name: str, text: str) -> None:
        """Output of a process, in pieces as it comes (lines may be split between pieces)."""
        with self._lock:
            if self.logs:
                self.logs.write(name, text)
            pending = self._partial.pop(name, "") + text
            lines = pending.split("\n")
            if lines[-1]:
                self._partial[name] = lines[-1]
            complete = [line.rstrip("\r") for line in lines[:-1]]
            shown = [line for line in complete if line.strip()]
            if shown:
                self._row(name).last_line = ROS_STAMP.sub(r"\1", shown[-1], count=1)
        if self.echo:
            for line in complete:
                self.output.line(f"[{self.shown(name)}] {line}")

    def exited(self, name: str, pid: int, code: int, command: list[str] | None = None) -> None:
        if self._partial.get(name):  # a last line without its newline
            self.output_text(name, "\n")
        with self._lock:
            row = self._row(name)
            row.code = code
            if name in self.stop_asked:
                row.state, row.detail = "stopped", f"exit code {code}"
            elif code == 0:
                row.state, row.detail = "exited", "exit code 0"
            elif self.stopping.is_set():
                row.state, row.detail = "stopped", f"exit code {code}"
            else:
                row.state, row.detail = "failed", f"exit code {code}"
            if self.logs:
                self.logs.note(name, f"process exited with code {code}")
        if self.echo:
            if code == 0:
                self.output.line(f"[INFO] [{self.shown(name)}]: process has finished cleanly [pid {pid}]")
            else:
                self.output.line(f"[ERROR] [{self.shown(name)}]: process has died [pid {pid}, exit code {code}, "
                                 f"cmd '{' '.join(command or [])}'].")

    def close(self) -> None:
        with self._lock:
            if self.logs:
                self.logs.close()
