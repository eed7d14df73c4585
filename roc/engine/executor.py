"""How tasks run: a pool of worker threads fed by the ReadyQueue; events go to handlers.

Handlers are called from the calling thread only, in event order, so they need no locking.
"""

from __future__ import annotations

import queue
import signal
import threading
import time
import traceback
from collections.abc import Callable, Iterable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

from roc.engine.events import (
    Event,
    RunFinished,
    TaskAborted,
    TaskFailed,
    TaskFinished,
    TaskQueued,
    TaskSkipped,
    TaskStarted,
    Tick,
)
from roc.engine.process import TaskCancelled, TaskContext, TaskError
from roc.engine.ready import ReadyQueue, Task

Handler = Callable[[Event], None]
TICK_SECONDS = 0.25


@dataclass
class RunResult:
    finished: list[str] = field(default_factory=list)
    failed: list[str] = field(default_factory=list)
    aborted: list[str] = field(default_factory=list)
    skipped: dict[str, str] = field(default_factory=dict)  # task -> the failed task that caused it
    not_started: list[str] = field(default_factory=list)
    interrupted: bool = False

    @property
    def ok(self) -> bool:
        return not (self.failed or self.aborted or self.skipped or self.not_started or self.interrupted)


def _work(task: Task, context: TaskContext) -> None:
    context.emit(TaskStarted(task.name))
    start = time.monotonic()
    try:
        if context.cancelled:
            raise TaskCancelled
        cached = task.action(context)
    except TaskCancelled:
        context.emit(TaskAborted(task.name, duration=time.monotonic() - start))
    except TaskError as error:
        context.emit(TaskFailed(task.name, duration=time.monotonic() - start, reason=str(error)))
    except Exception:  # noqa: BLE001 - a bug in an action must fail its task, not hang the run
        context.emit(TaskFailed(task.name, duration=time.monotonic() - start, reason=traceback.format_exc()))
    else:
        context.emit(TaskFinished(task.name, duration=time.monotonic() - start, cached=bool(cached)))


def execute(
    tasks: Iterable[Task],
    handlers: Iterable[Handler],
    workers: int,
    continue_on_error: bool = False,
) -> RunResult:
    """Run ``tasks`` respecting their dependencies with at most ``workers`` at once (0: no limit).

    Without ``continue_on_error`` the first failure stops the running tasks (aborted) and starts no
    more; with it, only the tasks depending on a failed one are skipped. Ctrl+C and SIGTERM stop every
    running process tree and end the run with ``interrupted`` set.
    """
    by_name = {t.name: t for t in tasks}
    ready = ReadyQueue(by_name)
    handlers = list(handlers)
    limit = workers if workers > 0 else max(1, len(by_name))
    events: queue.Queue[Event] = queue.Queue()
    running: dict[str, TaskContext] = {}
    result = RunResult()
    stopping = False

    def dispatch(event: Event) -> None:
        for handler in handlers:
            handler(event)

    def stop_running() -> None:
        for context in list(running.values()):
            threading.Thread(target=context.cancel, daemon=True).start()

    def settle(event: Event) -> None:
        nonlocal stopping
        if isinstance(event, TaskFinished):
            result.finished.append(event.task)
            ready.done(event.task)
        elif isinstance(event, TaskFailed):
            result.failed.append(event.task)
            if continue_on_error:
                blocked = [n for n in ready.downstream(event.task) if n not in result.skipped]
                ready.drop(blocked)
                for name in blocked:
                    result.skipped[name] = event.task
                    dispatch(TaskSkipped(name, because_of=event.task))
            elif not stopping:
                stopping = True
                stop_running()
        elif isinstance(event, TaskAborted):
            result.aborted.append(event.task)
        if isinstance(event, (TaskFinished, TaskFailed, TaskAborted)):
            running.pop(event.task, None)

    interrupt = threading.Event()

    def on_signal(signum, frame) -> None:  # noqa: ARG001
        # Only note it: raising here could leave a started task unaccounted for.
        interrupt.set()
        events.put(Tick(""))

    previous = {}
    if threading.current_thread() is threading.main_thread():
        previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    pool = ThreadPoolExecutor(max_workers=limit, thread_name_prefix="roc-worker")
    failure: BaseException | None = None

    def handle(event: Event) -> None:
        """Handlers see the event; the run's bookkeeping happens even if one of them fails."""
        nonlocal failure, stopping
        try:
            dispatch(event)
        except Exception as error:  # e.g. stdout closed under a JSON consumer: stop, then report it
            if failure is None:
                failure = error
            if not stopping:
                stopping = True
                stop_running()
        finally:
            settle(event)

    try:
        for name in by_name:
            handle(TaskQueued(name))
        while True:
            if interrupt.is_set() and not result.interrupted:
                result.interrupted = stopping = True
                stop_running()
            while not stopping and ready.has_ready() and len(running) < limit:
                task = ready.pop()
                if task.up_to_date:
                    handle(TaskFinished(task.name, cached=True))
                    continue
                context = TaskContext(task.name, events.put)
                pool.submit(_work, task, context)
                running[task.name] = context
            if not running:
                break
            try:
                event = events.get(timeout=TICK_SECONDS)
            except queue.Empty:
                event = Tick("")
            handle(event)
    finally:
        pool.shutdown(wait=True)
        while not events.empty():  # events emitted by the last workers while shutting down
            handle(events.get())
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    done = set(result.finished) | set(result.failed) | set(result.aborted) | set(result.skipped)
    result.not_started = [n for n in by_name if n not in done]
    handle(RunFinished("", interrupted=result.interrupted, not_started=tuple(result.not_started)))
    if failure is not None:
        raise failure
    return result
