"""Events emitted while tasks run. Workers never print; handlers turn events into output and logs.

Every task event names its task by ``kind`` (``build``, ``idl``, ``test``, ``probe``, ...) and ``task``
(what it works on: a package, a probe); ``key`` joins them, as the engine does. Events are frozen and
equal only to themselves (``eq=False``): a run compares none, and each method a dataclass generates
costs every build's start-up (so does a class without a docstring: dataclasses makes one from its
signature).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field


@dataclass(frozen=True, eq=False)
class Event:
    """Something that happened to task ``task`` of kind ``kind``, at ``time``."""

    task: str
    kind: str = "build"
    time: float = field(default_factory=time.time)

    @property
    def key(self) -> str:
        return task_key(self.kind, self.task)


def task_key(kind: str, name: str) -> str:
    """The engine's name of a task: the package name for builds (colcon's), ``kind:name`` otherwise."""
    return name if kind == "build" else f"{kind}:{name}"


@dataclass(frozen=True, eq=False)
class TaskQueued(Event):
    """The task is known to the run; it starts once its dependencies are done."""


@dataclass(frozen=True, eq=False)
class TaskRestoring(Event):
    """A worker looks for the task's result in a cache (a remote build cache) before running it; a
    TaskFinished with ``restored`` or a TaskStarted (a miss, its reason among the reasons) follows."""


@dataclass(frozen=True, eq=False)
class TaskStarted(Event):
    """The task runs (its up-to-date check found ``reasons`` to)."""

    reasons: tuple[str, ...] = ()  # why it is not up to date (empty when it has no up-to-date check)


@dataclass(frozen=True, eq=False)
class CommandStarted(Event):
    """The task started a command, in ``cwd``."""

    command: tuple[str, ...] = ()
    cwd: str = ""


@dataclass(frozen=True, eq=False)
class CommandEnded(Event):
    """A command of the task ended with ``returncode``."""

    command: tuple[str, ...] = ()
    returncode: int = 0


@dataclass(frozen=True, eq=False)
class TaskOutput(Event):
    """Output of the task's commands, as it came."""

    stream: str = "stdout"  # or "stderr"
    data: bytes = b""


@dataclass(frozen=True, eq=False)
class TaskFinished(Event):
    """The task succeeded, or was up to date (``cached``), or was restored from a cache."""

    duration: float = 0.0
    cached: bool = False  # skipped because it was up to date
    restored: bool = False  # not run: its result was fetched from a cache (after a TaskRestoring)
    worker: str = ""  # the cluster worker that ran it (roc work build --cluster); empty: it ran here


@dataclass(frozen=True, eq=False)
class TaskWarning(Event):
    """Something about a task the user should know that does not fail it (a remote cache that is down,
    a damaged cache entry)."""

    message: str = ""


@dataclass(frozen=True, eq=False)
class TaskFailed(Event):
    """The task failed, for ``reason``."""

    duration: float = 0.0
    reason: str = ""


@dataclass(frozen=True, eq=False)
class TaskAborted(Event):
    """Stopped while running, because another task failed or the user interrupted."""

    duration: float = 0.0


@dataclass(frozen=True, eq=False)
class TaskSkipped(Event):
    """Never started because a dependency failed or was aborted."""

    because_of: str = ""


@dataclass(frozen=True, eq=False)
class TestFailures(Event):
    """A test task's tests ran and some failed; the task itself still finishes, as in colcon (its
    result is "test failures", not a failure of the run)."""

    __test__ = False


@dataclass(frozen=True, eq=False)
class TestsNotRun(Event):
    """A test task's tool ran no test (pytest collected none); the task still finishes, as in colcon.
    ``reason``: why, e.g. the test files that skipped themselves while pytest imported them."""

    __test__ = False
    reason: str = ""


@dataclass(frozen=True, eq=False)
class ProbeResult(Event):
    """A probe's verdict (``pass``, ``fail``, ``error``), sent before its task ends: what it found
    (``message``, ``measured``) and what was expected."""

    status: str = "pass"
    message: str = ""
    expected: dict = field(default_factory=dict, hash=False)
    measured: object = field(default=None, hash=False)


@dataclass(frozen=True, eq=False)
class RunFinished(Event):
    """The whole run ended; ``task`` is empty."""

    interrupted: bool = False
    not_started: tuple[str, ...] = ()  # never started: the run stopped first


@dataclass(frozen=True, eq=False)
class Tick(Event):
    """Sent to handlers while the executor waits, so that a live status line can refresh."""
