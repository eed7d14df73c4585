"""Events emitted while tasks run. Workers never print; handlers turn events into output and logs.

Every task event names its task by ``kind`` (``build``, ``idl``, ``test``, ``probe``, ...) and ``task``
(what it works on: a package, a probe); ``key`` joins them, as the engine does. An event is never
changed once made, and is equal only to itself.

Plain classes with slots, written out as colcon's events are: as dataclasses, the methods generated
for these seventeen classes cost every build's start-up some 7 ms (a twentieth of a no-op build).
"""

from __future__ import annotations

import time as clock

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any


class Event:
    """Something that happened to task ``task`` of kind ``kind``, at ``time`` (seconds since the epoch;
    now when not given)."""

    __slots__ = ("task", "kind", "time")

    def __init__(self, task: str, kind: str = "build", *, time: float | None = None) -> None:
        self.task = task
        self.kind = kind
        self.time = clock.time() if time is None else time

    @property
    def key(self) -> str:
        return task_key(self.kind, self.task)

    def fields(self) -> dict[str, Any]:
        """Every field by name, the base class's first (an event log's record)."""
        return {name: getattr(self, name) for cls in reversed(type(self).__mro__)
                for name in cls.__dict__.get("__slots__", ())}

    def for_task(self, task: str, kind: str) -> Event:
        """This event, told of task ``task`` of kind ``kind`` (a cluster worker's events, emitted here)."""
        import copy

        event = copy.copy(self)
        event.task, event.kind = task, kind
        return event

    def __repr__(self) -> str:
        return f"{type(self).__name__}({', '.join(f'{k}={v!r}' for k, v in self.fields().items())})"


def task_key(kind: str, name: str) -> str:
    """The engine's name of a task: the package name for builds (colcon's), ``kind:name`` otherwise."""
    return name if kind == "build" else f"{kind}:{name}"


class TaskQueued(Event):
    """The task is known to the run; it starts once its dependencies are done."""

    __slots__ = ()


class TaskRestoring(Event):
    """A worker looks for the task's result in a cache (a remote build cache) before running it; a
    TaskFinished with ``restored`` or a TaskStarted (a miss, its reason among the reasons) follows."""

    __slots__ = ()


class TaskStarted(Event):
    """The task runs; ``reasons``: why it was not up to date (empty when it has no up-to-date check)."""

    __slots__ = ("reasons",)

    def __init__(self, task: str, kind: str = "build", *, reasons: tuple[str, ...] = (),
                 time: float | None = None) -> None:
        super().__init__(task, kind, time=time)
        self.reasons = reasons


class CommandStarted(Event):
    """The task started ``command``, in ``cwd``."""

    __slots__ = ("command", "cwd")

    def __init__(self, task: str, kind: str = "build", *, command: tuple[str, ...] = (), cwd: str = "",
                 time: float | None = None) -> None:
        super().__init__(task, kind, time=time)
        self.command = command
        self.cwd = cwd


class CommandEnded(Event):
    """A command of the task ended with ``returncode``."""

    __slots__ = ("command", "returncode")

    def __init__(self, task: str, kind: str = "build", *, command: tuple[str, ...] = (), returncode: int = 0,
                 time: float | None = None) -> None:
        super().__init__(task, kind, time=time)
        self.command = command
        self.returncode = returncode


class TaskOutput(Event):
    """Output of the task's commands, as it came on ``stream`` (``stdout`` or ``stderr``)."""

    __slots__ = ("stream", "data")

    def __init__(self, task: str, kind: str = "build", *, stream: str = "stdout", data: bytes = b"",
                 time: float | None = None) -> None:
        super().__init__(task, kind, time=time)
        self.stream = stream
        self.data = data


class TaskFinished(Event):
    """The task succeeded; ``cached``: it was up to date and did not run; ``restored``: its result was
    fetched from a cache (after a TaskRestoring); ``worker``: the cluster worker that ran it (roc work
    build --cluster; empty: it ran here)."""

    __slots__ = ("duration", "cached", "restored", "worker")

    def __init__(self, task: str, kind: str = "build", *, duration: float = 0.0, cached: bool = False,
                 restored: bool = False, worker: str = "", time: float | None = None) -> None:
        super().__init__(task, kind, time=time)
        self.duration = duration
        self.cached = cached
        self.restored = restored
        self.worker = worker


class TaskWarning(Event):
    """Something about a task the user should know that does not fail it (a remote cache that is down,
    a damaged cache entry)."""

    __slots__ = ("message",)

    def __init__(self, task: str, kind: str = "build", *, message: str = "", time: float | None = None) -> None:
        super().__init__(task, kind, time=time)
        self.message = message


class TaskFailed(Event):
    """The task failed, for ``reason``."""

    __slots__ = ("duration", "reason")

    def __init__(self, task: str, kind: str = "build", *, duration: float = 0.0, reason: str = "",
                 time: float | None = None) -> None:
        super().__init__(task, kind, time=time)
        self.duration = duration
        self.reason = reason


class TaskAborted(Event):
    """Stopped while running, because another task failed or the user interrupted."""

    __slots__ = ("duration",)

    def __init__(self, task: str, kind: str = "build", *, duration: float = 0.0, time: float | None = None) -> None:
        super().__init__(task, kind, time=time)
        self.duration = duration


class TaskSkipped(Event):
    """Never started because a dependency failed or was aborted (``because_of``)."""

    __slots__ = ("because_of",)

    def __init__(self, task: str, kind: str = "build", *, because_of: str = "", time: float | None = None) -> None:
        super().__init__(task, kind, time=time)
        self.because_of = because_of


class TestFailures(Event):
    """A test task's tests ran and some failed; the task itself still finishes, as in colcon (its
    result is "test failures", not a failure of the run)."""

    __slots__ = ()
    __test__ = False


class TestsNotRun(Event):
    """A test task's tool ran no test (pytest collected none); the task still finishes, as in colcon.
    ``reason``: why, e.g. the test files that skipped themselves while pytest imported them."""

    __slots__ = ("reason",)
    __test__ = False

    def __init__(self, task: str, kind: str = "build", *, reason: str = "", time: float | None = None) -> None:
        super().__init__(task, kind, time=time)
        self.reason = reason


class ProbeResult(Event):
    """A probe's verdict (``pass``, ``fail``, ``error``), sent before its task ends: what it found
    (``message``, ``measured``) and what was expected."""

    __slots__ = ("status", "message", "expected", "measured")

    def __init__(self, task: str, kind: str = "build", *, status: str = "pass", message: str = "",
                 expected: dict | None = None, measured: object = None, time: float | None = None) -> None:
        super().__init__(task, kind, time=time)
        self.status = status
        self.message = message
        self.expected = {} if expected is None else expected
        self.measured = measured


class RunFinished(Event):
    """The whole run ended; ``task`` is empty. ``not_started``: the tasks that never started (the run
    stopped first)."""

    __slots__ = ("interrupted", "not_started")

    def __init__(self, task: str, kind: str = "build", *, interrupted: bool = False,
                 not_started: tuple[str, ...] = (), time: float | None = None) -> None:
        super().__init__(task, kind, time=time)
        self.interrupted = interrupted
        self.not_started = not_started


class Tick(Event):
    """Sent to handlers while the executor waits, so that a live status line can refresh."""

    __slots__ = ()
