"""The orphan guard: stops every process a ``roc launch`` started once that roc is gone, however it went
(Ctrl+C, SIGTERM, a closed terminal, or SIGKILL, which no process can catch).

roc starts it first, as ``python -S -E guard.py TOKEN`` in a session of its own (so no signal meant for
roc's terminal reaches it), with a pipe as its stdin. roc writes one line per process it starts,
``pid PID STARTTIME``, and ``group PGID`` for a process group of its own. When the pipe closes (roc
exited or was killed: the kernel closes it either way), the guard stops:

- the recorded processes (unless their PID now names another process: the start time must match),
- every process of a recorded group,
- every process whose environment holds ``ROC_LAUNCH_ID=TOKEN`` (roc puts it in the environment of
  everything it starts, so grandchildren and processes that left their group are found too),
- and every descendant of those,

with SIGTERM, sent again every RESEND_SECONDS to what still runs, then SIGKILL for what still runs after
the grace period. Linux only (``/proc``); the
standard library only, so that it starts in milliseconds. roc runs the same ``sweep`` itself when it
ends normally, so nothing is left even before the guard notices.
"""

from __future__ import annotations

import os
import signal
import sys
import time
from dataclasses import dataclass

TOKEN_VARIABLE = "ROC_LAUNCH_ID"
GRACE_SECONDS = 5.0
# SIGTERM goes again this often during the grace. rclpy's handler (7.x, Jazzy) wakes the node's executor and
# only then shuts its context down, and that shutdown wakes nothing: an executor that looked at its
# context in between waits again, until a timer or a message wakes it, and a node with neither slept
# until SIGKILL. A second SIGTERM wakes it to a context already shut down, and it ends.
RESEND_SECONDS = 0.5


@dataclass
class Proc:
    pid: int
    ppid: int
    pgid: int
    start: int
    state: str


def read_proc(pid: int) -> Proc | None:
    """A process's parent, group, start time (clock ticks since boot) and state, from /proc/PID/stat."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as handle:
            text = handle.read().decode(errors="replace")
    except OSError:
        return None
    fields = text[text.rfind(")") + 2:].split()  # the command name may hold spaces and parentheses
    return Proc(pid, int(fields[1]), int(fields[2]), int(fields[19]), fields[0])


def start_time(pid: int) -> int | None:
    proc = read_proc(pid)
    return proc.start if proc else None


def _has_token(pid: int, marker: bytes) -> bool:
    try:
        with open(f"/proc/{pid}/environ", "rb") as handle:
            return marker in handle.read().split(b"\0")
    except OSError:
        return False


def targets(token: str, recorded: dict[int, int], groups: set[int]) -> list[int]:
    """The live processes to stop (see the module's docstring); never this process."""
    marker = f"{TOKEN_VARIABLE}={token}".encode()
    table = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            proc = read_proc(int(entry))
            if proc is not None and proc.state not in ("Z", "X"):
                table[proc.pid] = proc
    chosen = {pid for pid, proc in table.items()
              if recorded.get(pid) == proc.start or proc.pgid in groups or _has_token(pid, marker)}
    grew = True
    while grew:  # descendants, however deep
        more = {pid for pid, proc in table.items() if proc.ppid in chosen} - chosen
        chosen |= more
        grew = bool(more)
    chosen.discard(os.getpid())
    return sorted(chosen)


def _signal_all(pids: list[int], signum: int) -> None:
    for pid in pids:
        try:
            os.kill(pid, signum)
        except OSError:
            pass


def _alive(pids: list[int]) -> list[int]:
    alive = []
    for pid in pids:
        proc = read_proc(pid)
        if proc is not None and proc.state not in ("Z", "X"):
            alive.append(pid)
    return alive


def sweep(token: str, recorded: dict[int, int] | None = None, groups: set[int] | None = None,
          grace: float = GRACE_SECONDS) -> list[int]:
    """Stop every process of the run (SIGTERM, again every RESEND_SECONDS, then SIGKILL after ``grace``);
    the PIDs it found."""
    found = targets(token, recorded or {}, groups or set())
    if not found:
        return found
    _signal_all(found, signal.SIGTERM)
    deadline = time.monotonic() + grace
    resend = time.monotonic() + RESEND_SECONDS
    while (alive := _alive(found)) and time.monotonic() < deadline:
        if time.monotonic() >= resend:
            _signal_all(alive, signal.SIGTERM)
            resend += RESEND_SECONDS
        time.sleep(0.05)
    _signal_all(_alive(found), signal.SIGKILL)
    return found


class Guard:
    """roc's side: starts the guard process, tells it each process roc starts, and on ``close`` stops
    what is left itself (then the guard, finding nothing, exits)."""

    def __init__(self) -> None:
        import subprocess
        import uuid

        self.token = f"{os.getpid()}-{uuid.uuid4().hex[:12]}"
        self.recorded: dict[int, int] = {}
        self.groups: set[int] = set()
        self._process = subprocess.Popen(
            [sys.executable, "-S", "-E", os.path.abspath(__file__), self.token], stdin=subprocess.PIPE,
            stdout=subprocess.DEVNULL, start_new_session=True, env={"PATH": os.environ.get("PATH", "")})

    def environment(self, base: dict[str, str]) -> dict[str, str]:
        """``base`` with the run's token, for every process roc starts."""
        return {**base, TOKEN_VARIABLE: self.token}

    def _send(self, line: str) -> None:
        stdin = self._process.stdin
        try:
            if stdin is not None:
                stdin.write(line.encode() + b"\n")
                stdin.flush()
        except OSError:
            pass

    def record(self, pid: int) -> None:
        started = start_time(pid)
        if started is not None:
            self.recorded[pid] = started
            self._send(f"pid {pid} {started}")

    def group(self, pgid: int) -> None:
        self.groups.add(pgid)
        self._send(f"group {pgid}")

    def close(self, grace: float = GRACE_SECONDS) -> list[int]:
        """Stop what is left of the run, then let the guard go; the PIDs that were still running."""
        left = sweep(self.token, self.recorded, self.groups, grace)
        if self._process.stdin is not None:
            try:
                self._process.stdin.close()
            except OSError:
                pass
        self._process.wait()
        return left


def main(argv: list[str]) -> int:
    token = argv[0]
    for signum in (signal.SIGINT, signal.SIGHUP, signal.SIGPIPE):
        signal.signal(signum, signal.SIG_IGN)
    recorded: dict[int, int] = {}
    groups: set[int] = set()
    for line in sys.stdin.buffer:  # until roc's end of the pipe closes
        words = line.split()
        if len(words) == 3 and words[0] == b"pid":
            recorded[int(words[1])] = int(words[2])
        elif len(words) == 2 and words[0] == b"group":
            groups.add(int(words[1]))
    sweep(token, recorded, groups)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
