"""What is ready to run: Kahn's algorithm over a task graph, critical path first."""

from __future__ import annotations

from collections.abc import Callable, Iterable

from roc.engine.events import task_key
from roc.engine.process import TaskContext


class Task:
    """A node of the graph. ``action`` runs in a worker; it raises TaskError to fail.

    ``check``, when given, runs when the task is about to be dispatched (after its dependencies have
    finished, so it sees what they produced) and returns the reasons the task must run; an empty list
    finishes the task as cached without taking a worker.

    ``restore``, when given, runs in the worker before the action: it fetches the task's result from a
    cache and returns None when it did (the action does not run), else why not ("" for no reason worth
    telling), added to the reasons of the task's start.

    A plain class (as are the engine's events): dataclasses costs every build's start-up 8 ms.
    """

    def __init__(self, name: str, dependencies: set[str], action: Callable, kind: str = "build",
                 weight: float = 1.0, check: Callable[[], list[str]] | None = None,
                 restore: Callable[[TaskContext], str | None] | None = None) -> None:
        self.name = name  # what the task works on (a package, a probe)
        self.dependencies = dependencies  # keys of the tasks it waits for
        self.action = action  # (TaskContext) -> None
        self.kind = kind  # build, idl, test, probe, ...
        self.weight = weight  # expected duration (seconds, or 1.0 when unknown)
        self.check = check
        self.restore = restore

    @property
    def key(self) -> str:
        return task_key(self.kind, self.name)

    def __repr__(self) -> str:
        return f"Task({self.key!r})"


class ReadyQueue:
    """Hands out tasks whose dependencies have all finished, longest remaining chain first.

    The priority of a task is its weight plus the largest priority among the tasks that depend on
    it, so the chain that bounds the total time starts as early as possible.
    """

    def __init__(self, tasks: dict[str, Task]) -> None:
        self.tasks = tasks  # by key
        names = tasks.keys()
        self._waiting_on = {n: set(t.dependencies) & names for n, t in self.tasks.items()}
        self._dependents: dict[str, set[str]] = {n: set() for n in names}
        for name, waiting in self._waiting_on.items():
            for dependency in waiting:
                self._dependents[dependency].add(name)
        self._priority: dict[str, float] = {}
        for name in self._reverse_topological():
            later = [self._priority[d] for d in self._dependents[name]]
            self._priority[name] = self.tasks[name].weight + max(later, default=0.0)
        self._ready = {n for n, waiting in self._waiting_on.items() if not waiting}

    def _reverse_topological(self) -> list[str]:
        remaining = {n: len(d) for n, d in self._dependents.items()}
        order = [n for n, count in remaining.items() if count == 0]
        for name in order:  # the list grows while iterating: breadth-first from the sinks
            for dependency in self._waiting_on[name]:
                remaining[dependency] -= 1
                if remaining[dependency] == 0:
                    order.append(dependency)
        if len(order) != len(self.tasks):
            raise ValueError("the task graph has a cycle")
        return order

    def priority(self, name: str) -> float:
        """The length of the longest chain of work from ``name`` on (its weight included)."""
        return self._priority[name]

    def has_ready(self) -> bool:
        return bool(self._ready)

    def pop(self) -> Task:
        """The ready task with the highest priority (ties: alphabetical)."""
        name = min(self._ready, key=lambda n: (-self._priority[n], n))
        self._ready.remove(name)
        return self.tasks[name]

    def done(self, name: str) -> None:
        """``name`` succeeded: its dependents may become ready."""
        for dependent in self._dependents[name]:
            waiting = self._waiting_on[dependent]
            waiting.discard(name)
            if not waiting:
                self._ready.add(dependent)

    def downstream(self, name: str) -> list[str]:
        """Every task that depends on ``name``, directly or not (they can no longer run)."""
        seen: list[str] = []
        stack = sorted(self._dependents[name])
        while stack:
            current = stack.pop()
            if current in seen:
                continue
            seen.append(current)
            stack.extend(sorted(self._dependents[current]))
        return seen

    def drop(self, names: Iterable[str]) -> None:
        """Remove tasks that will never run (skipped) from the ready set."""
        for name in names:
            self._ready.discard(name)
