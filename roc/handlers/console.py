"""colcon-style console output: start/end lines, each package's stderr as one block, a summary."""

from __future__ import annotations

import sys
import time
from collections.abc import Collection

from roc.engine.events import (
    Event,
    RunFinished,
    TaskAborted,
    TaskFailed,
    TaskFinished,
    TaskOutput,
    TaskQueued,
    TaskSkipped,
    TaskStarted,
    TaskWarning,
    TestFailures,
)
from roc.handlers.logs import task_log_folder
from roc.render import plural

TYPE_CHECKING = False  # typing is not imported at run time (start-up time of every build)
if TYPE_CHECKING:
    from typing import TextIO


def format_duration(seconds: float) -> str:
    if seconds < 10:
        return f"{seconds:.2f}s"
    if seconds < 60:
        return f"{seconds:.1f}s"
    minutes, rest = divmod(int(round(seconds)), 60)
    return f"{minutes}min {rest}s"


def _names(labels: Collection[str]) -> str:
    """Labels in a summary line, sorted: space-separated as colcon lists packages, or comma-separated
    when a label has a space of its own (a probe: ``node /ghost_node``)."""
    return (", " if any(" " in label for label in labels) else " ").join(sorted(labels))


def _count(labels: list[str], noun: str = "package") -> str:
    """``3 packages``, or ``2 packages and 1 idl task``: a task of the run's own kind is labelled by
    what it works on (a ``noun``: package, probe), one of another kind by its key ``kind:name`` (such
    labels hold no colon)."""
    packages = [label for label in labels if ":" not in label]
    other_kinds: dict[str, int] = {}
    for label in labels:
        if ":" in label:
            kind = label.split(":", 1)[0]
            other_kinds[kind] = other_kinds.get(kind, 0) + 1
    parts = [plural(len(packages), noun)] if packages or not other_kinds else []
    parts += [plural(n, f"{kind} task") for kind, n in sorted(other_kinds.items())]
    return " and ".join(parts)


class ConsoleHandler:
    """Prints as colcon's console_start_end, console_stderr and summary handlers do.

    ``direct`` echoes all output as it comes (console_direct+); ``cohesion`` prints each package's whole
    output when it ends (console_cohesion+). Tasks of the run's own ``kind`` are named as colcon names
    them (the package: ``Starting >>> pkg``), other tasks by their key (``idl:pkg``).
    """

    def __init__(self, stream: TextIO = sys.stdout, *, start_end: bool = True, stderr: bool = True,
                 summary: bool = True, direct: bool = False, cohesion: bool = False, log_path: str | None = None,
                 status=None, kind: str = "build", cached_label: str = "up to date (not rebuilt)",
                 finished_note=None, failed_note=None, noun: str = "package"):
        self.stream = stream
        self.noun = noun  # what a task of the run's own kind is, in the summary
        self.cached_label = cached_label  # how the summary names tasks that finished without running
        self.finished_note = finished_note  # (task key) -> text appended to its "Finished" line
        self.failed_note = failed_note  # (task key, its stderr) -> text appended to its "Failed" line
        self.status = status  # a StatusLine on a terminal: lines are printed above it
        self.start_end, self.stderr, self.summary = start_end, stderr, summary
        self.direct, self.cohesion = direct, cohesion
        self.log_path = log_path
        self.kind = kind  # the run's own kind of task (its logs are not in a kind subfolder)
        self.started_at = time.monotonic()
        self._stderr: dict[str, bytearray] = {}
        self._all: dict[str, bytearray] = {}
        self.finished: list[str] = []
        self.cached: list[str] = []
        self.restored: list[str] = []  # fetched from the remote build cache, not run
        self.elsewhere: list[str] = []  # run on a cluster worker (and among ``finished``)
        self.failed: list[str] = []
        self.aborted: list[str] = []
        self.skipped: dict[str, str] = {}
        self.test_failures: list[str] = []
        self._labels: dict[str, str] = {}  # task key -> the name printed

    def label(self, event: Event) -> str:
        """How a task is named on the console: its name for the run's own kind, else its key."""
        return event.task if event.kind == self.kind else event.key

    def close(self) -> None:
        """Give the terminal back (the live status line) if the run ended without RunFinished."""
        if self.status is not None:
            self.status.live.stop()
            self.status = None

    def _print(self, text: str) -> None:
        if self.status is not None:
            self.status.print(text)
            return
        self.stream.write(text + "\n")
        self.stream.flush()

    def _warn(self, text: str) -> None:
        if self.status is not None:
            self.status.print(text)
        else:
            print(text, file=sys.stderr, flush=True)

    def __call__(self, event: Event) -> None:
        if isinstance(event, TaskOutput):
            if self.direct:
                target = sys.stderr if event.stream == "stderr" else self.stream
                target.write(event.data.decode(errors="replace"))
                target.flush()
            if event.stream == "stderr":
                self._stderr.setdefault(event.key, bytearray()).extend(event.data)
            self._all.setdefault(event.key, bytearray()).extend(event.data)
        elif isinstance(event, TaskQueued):
            self._labels[event.key] = self.label(event)
        elif isinstance(event, TaskStarted):
            if self.start_end:
                self._print(f"Starting >>> {self.label(event)}")
        elif isinstance(event, (TaskFinished, TaskFailed, TaskAborted)):
            self._ended(event)
        elif isinstance(event, TaskSkipped):
            self.skipped[self.label(event)] = self._labels.get(event.because_of, event.because_of)
        elif isinstance(event, TestFailures):
            self.test_failures.append(self.label(event))
        elif isinstance(event, TaskWarning):
            self._warn(f"roc: warning: {self.label(event)}: {event.message}")
        elif isinstance(event, RunFinished):
            if self.status is not None:
                self.status(event)  # stops the live line, before the summary
                self.status = None
            if self.summary:
                self._print_summary(event)
        if self.status is not None:
            self.status(event)

    def _ended(self, event: TaskFinished | TaskFailed | TaskAborted) -> None:
        key, name = event.key, self.label(event)  # name: the package for the run's own kind (as colcon)
        if self.cohesion and key in self._all:
            self._print(f"--- output: {name}\n{self._all[key].decode(errors='replace').rstrip()}\n---")
        elif self.stderr and not self.direct and key in self._stderr:
            where = f" (log: {self.log_path}/{task_log_folder(event, self.kind)}/stderr.log)" if self.log_path else ""
            self._print(f"--- stderr: {name}{where}\n{self._stderr[key].decode(errors='replace').rstrip()}\n---")
        if isinstance(event, TaskFinished) and event.restored:
            self.restored.append(name)
            line = f"Restored <<< {name} [from cache, {format_duration(event.duration)}]"
        elif isinstance(event, TaskFinished):
            (self.cached if event.cached else self.finished).append(name)
            where = f" on {event.worker}" if event.worker else ""
            if event.worker:
                self.elsewhere.append(name)
            line = f"Finished <<< {name} [{'cached' if event.cached else format_duration(event.duration)}{where}]"
            if self.finished_note:
                line += self.finished_note(key)
        elif isinstance(event, TaskFailed):
            self.failed.append(name)
            reason = event.reason.strip().splitlines()[-1] if event.reason.strip() else "failed"
            line = f"Failed   <<< {name} [{format_duration(event.duration)}, {reason}]"
            if self.failed_note:
                line += self.failed_note(key, self._stderr.get(key, b"").decode(errors="replace"))
        else:
            self.aborted.append(name)
            line = f"Aborted  <<< {name} [{format_duration(event.duration)}]"
        if isinstance(event, TaskFinished) and (event.cached or not self.start_end):
            return  # up-to-date packages are counted in the summary
        self._print(line)

    def _print_summary(self, event: RunFinished) -> None:
        total = format_duration(time.monotonic() - self.started_at)
        lines = ["", f"Summary: {_count(self.finished + self.restored + self.cached, self.noun)} finished [{total}]"]
        if self.elsewhere:
            here = len(self.finished) - len(self.elsewhere)
            done = "built" if self.kind == "build" else "run"
            counts = [f"{here} {done} here", f"{len(self.elsewhere)} on the cluster"]
            counts += [f"{len(self.restored)} restored from the remote cache"] if self.restored else []
            lines[-1] += f" ({', '.join([*counts, f'{len(self.cached)} up to date'])})"
        elif self.restored:
            lines[-1] += (f" ({len(self.finished)} built, {len(self.restored)} restored from the remote cache, "
                          f"{len(self.cached)} up to date)")
        if self.cached:
            names = f": {_names(self.cached)}" if len(self.cached) <= 10 else ""
            lines.append(f"  {_count(self.cached, self.noun)} {self.cached_label}{names}")
        if self.failed:
            lines.append(f"  {_count(self.failed, self.noun)} failed: {_names(self.failed)}")
        if self.aborted:
            lines.append(f"  {_count(self.aborted, self.noun)} aborted: {_names(self.aborted)}")
        if self.skipped:
            causes = " ".join(f"{name} (needs {cause})" for name, cause in sorted(self.skipped.items()))
            lines.append(f"  {_count(list(self.skipped), self.noun)} skipped because a dependency failed: {causes}")
        with_stderr = sorted(self._labels.get(key, key) for key in self._stderr)
        if with_stderr:
            lines.append(f"  {_count(with_stderr, self.noun)} had stderr output: {_names(with_stderr)}")
        if self.test_failures:
            lines.append(f"  {_count(self.test_failures, self.noun)} had test failures: "
                         f"{_names(self.test_failures)}")
        if event.not_started:
            lines.append(f"  {_count(list(event.not_started), self.noun)} not processed")
        if event.interrupted:
            lines.append("  interrupted by the user")
        self._print("\n".join(lines))
