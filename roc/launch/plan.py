"""A roc.toml system as engine tasks: one task of kind ``process`` per process, after one ``probe`` task
per condition it waits for (each probing until the condition holds or the system's timeout), or after
the task of another process (``process NAME started``). The engine's order is the start-up order
(``--explain`` says what each process waits for: roc/launch/explain.py)."""

from __future__ import annotations

import threading
from collections.abc import Callable

from roc.check.probes import KIND as PROBE
from roc.engine.events import task_key
from roc.engine.process import TaskCancelled, TaskContext
from roc.engine.ready import ReadyQueue, Task
from roc.errors import UsageError
from roc.launch.system import ProcessSpec, System

PROCESS = "process"


class LazySession:
    """The probes' one graph session (roc.ros.client.Session), made when the first probe asks, so that a
    system without conditions, or one only explained, never reaches the graph."""

    def __init__(self, use_daemon: bool = True, spin_time: float | None = None):
        self.use_daemon, self.spin_time = use_daemon, spin_time
        self._session = None
        self._lock = threading.Lock()

    def _get(self):
        with self._lock:
            if self._session is None:
                from roc.ros.client import Session

                self._session = Session(use_daemon=self.use_daemon, spin_time=self.spin_time, long_lived=True)
            return self._session

    def query(self, *args, **kwargs):
        return self._get().query(*args, **kwargs)

    def stream(self, *args, **kwargs):
        return self._get().stream(*args, **kwargs)

    def close(self) -> None:
        if self._session is not None:
            self._session.close()


def plan(system: System, start: Callable[[ProcessSpec], None], session: LazySession,
         stopped: Callable[[], bool]) -> list[Task]:
    """The tasks that start ``system``: ``start`` starts one process; the probes share ``session``."""
    from roc.check.probes import probe_task

    tasks: dict[str, Task] = {}
    for spec in system.processes:
        dependencies = set()
        for condition in spec.after:
            if condition.expectation is None:
                dependencies.add(task_key(PROCESS, condition.process))
                continue
            expectation = condition.expectation
            key = task_key(PROBE, expectation.label)
            if key not in tasks:
                tasks[key] = probe_task(expectation, session, timeout=min(system.timeout, 10.0),
                                        rate_window=2.0, wait=system.timeout, stopped=stopped)
            dependencies.add(key)
        tasks[task_key(PROCESS, spec.label)] = Task(name=spec.label, dependencies=dependencies, kind=PROCESS,
                                                    action=_starter(spec, start, stopped))
    try:
        ReadyQueue(dict(tasks))
    except ValueError:
        raise UsageError(f"{system.path}: the processes of [launch.{system.name}] wait for each other in a circle "
                         "('process NAME started' conditions); break the circle") from None
    return list(tasks.values())


def _starter(spec: ProcessSpec, start: Callable[[ProcessSpec], None], stopped: Callable[[], bool]):
    def action(context: TaskContext) -> None:
        if context.cancelled or stopped():
            raise TaskCancelled
        start(spec)
    return action


def start_order(tasks: list[Task]) -> list[Task]:
    """The tasks in start-up order: by how many tasks wait before them (a probe counts as one), then as
    declared."""
    by_key = {task.key: task for task in tasks}
    depth: dict[str, int] = {}

    def depth_of(key: str) -> int:
        if key not in depth:
            task = by_key[key]
            depth[key] = 1 + max((depth_of(d) for d in task.dependencies), default=-1)
        return depth[key]

    return sorted(tasks, key=lambda task: depth_of(task.key))
