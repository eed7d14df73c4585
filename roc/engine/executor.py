"""How tasks run: a worker thread per running task, fed by the ReadyQueue; events go to handlers.

Handlers are called from the calling thread only, in event order, so they need no locking.
"""

from __future__ import annotations

import queue
import signal
import threading
import time
from collections.abc import Callable, Iterable

from roc.engine.events import (
    Event,
    RunFinished,
    TaskAborted,
    TaskFailed,
    TaskFinished,
    TaskQueued,
    TaskRestoring,
    TaskSkipped,
    TaskStarted,
    Tick,
)
from roc.engine.process import RanElsewhere, TaskCancelled, TaskContext, TaskError
from roc.engine.ready import ReadyQueue, Task
from roc.messages import warn

Handler = Callable[[Event], None]
TICK_SECONDS = 0.25


class RunResult:
    """What became of each task of a run."""

    def __init__(self) -> None:
        self.finished: list[str] = []
        self.failed: list[str] = []
        self.aborted: list[str] = []
        self.skipped: dict[str, str] = {}  # task -> the failed task that caused it
        self.not_started: list[str] = []
        self.interrupted = False

    @property
    def ok(self) -> bool:
        return not (self.failed or self.aborted or self.skipped or self.not_started or self.interrupted)


def _work(task: Task, context: TaskContext, reasons: tuple[str, ...]) -> None:
    start = time.monotonic()
    if task.restore is not None and not context.cancelled:
        context.emit(TaskRestoring(task.name, task.kind))
        try:
            missed = task.restore(context)
        except Exception as error:  # noqa: BLE001 - a cache that breaks is a miss: the task runs
            missed = f"restore failed: {type(error).__name__}: {error}"
        if missed is None:
            context.emit(TaskFinished(task.name, task.kind, duration=time.monotonic() - start, restored=True))
            return
        reasons = (*reasons, missed) if missed else reasons
    context.emit(TaskStarted(task.name, task.kind, reasons=reasons))
    start = time.monotonic()
    try:
        if context.cancelled:
            raise TaskCancelled
        outcome = task.action(context)
    except TaskCancelled:
        context.emit(TaskAborted(task.name, task.kind, duration=time.monotonic() - start))
    except TaskError as error:
        context.emit(TaskFailed(task.name, task.kind, duration=time.monotonic() - start, reason=str(error)))
    except Exception:  # noqa: BLE001 - a bug in an action must fail its task, not hang the run
        import traceback

        context.emit(TaskFailed(task.name, task.kind, duration=time.monotonic() - start,
                                reason=traceback.format_exc()))
    else:
        if isinstance(outcome, RanElsewhere):
            context.emit(TaskFinished(task.name, task.kind, duration=outcome.duration, worker=outcome.worker))
        else:
            context.emit(TaskFinished(task.name, task.kind, duration=time.monotonic() - start))


def _check(task: Task) -> list[str] | None:
    """The reasons ``task`` must run (empty: up to date), or None when it has no check."""
    return None if task.check is None else list(task.check())


def execute(
    tasks: Iterable[Task],
    handlers: Iterable[Handler],
    workers: int | Callable[[], int],
    continue_on_error: bool = False,
    kind: str = "build",
    stop: threading.Event | None = None,
) -> RunResult:
    """Run ``tasks`` respecting their dependencies with at most ``workers`` at once (0: no limit; a
    function: asked again before each dispatch, for a limit that changes, such as a cluster's workers).

    Without ``continue_on_error`` the first failure stops the running tasks (aborted) and starts no
    more; with it, only the tasks depending on a failed one are skipped. ``kind`` is the run's own kind
    of task (``build``, ``test``, ``probe``), which the final RunFinished event carries. Ctrl+C and
    SIGTERM stop every running process tree and end the run with ``interrupted`` set, as does setting
    ``stop`` (for a run in a thread other than the main one, where no signal reaches it: ``roc tui``).
    A handler that raises is reported
    on stderr and left out of the rest of the run (the run goes on), except for a closed stdout
    (BrokenPipeError), which stops the run and is raised at its end.
    """
    by_name = {t.key: t for t in tasks}
    ready = ReadyQueue(by_name)
    handlers = list(handlers)

    def limit() -> int:
        count = workers() if callable(workers) else workers
        return count if count > 0 else max(1, len(by_name))

    events: queue.Queue[Event] = queue.Queue()
    running: dict[str, TaskContext] = {}
    result = RunResult()
    stopping = False

    def dispatch(event: Event) -> None:
        for handler in list(handlers):
            try:
                handler(event)
            except BrokenPipeError:
                raise
            except Exception as error:  # noqa: BLE001 - one broken output must not break the build
                handlers.remove(handler)
                name = getattr(handler, "name", getattr(handler, "__name__", type(handler).__name__))
                warn(f"event handler '{name}' failed and was disabled: {type(error).__name__}: {error}")

    def stop_running() -> None:
        for context in list(running.values()):
            threading.Thread(target=context.cancel, daemon=True).start()

    def settle(event: Event) -> None:
        nonlocal stopping
        key = event.key
        if isinstance(event, TaskFinished):
            result.finished.append(key)
            ready.done(key)
        elif isinstance(event, TaskFailed):
            result.failed.append(key)
            if continue_on_error:
                blocked = [k for k in ready.downstream(key) if k not in result.skipped]
                ready.drop(blocked)
                for blocked_key in blocked:
                    result.skipped[blocked_key] = key
                    task = by_name[blocked_key]
                    dispatch(TaskSkipped(task.name, task.kind, because_of=key))
            elif not stopping:
                stopping = True
                stop_running()
        elif isinstance(event, TaskAborted):
            result.aborted.append(key)
        if isinstance(event, (TaskFinished, TaskFailed, TaskAborted)):
            running.pop(key, None)

    interrupt = stop or threading.Event()

    def on_signal(signum, frame) -> None:  # noqa: ARG001
        # Only note it: raising here could leave a started task unaccounted for.
        interrupt.set()
        events.put(Tick(""))

    previous = {}
    if threading.current_thread() is threading.main_thread():
        previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    # a thread per running task (at most limit() at once); no pool: concurrent.futures costs a no-op
    # build's start-up more than its threads do
    threads: list[threading.Thread] = []
    failure: BaseException | None = None

    def handle(event: Event) -> None:
        """Handlers see the event; the run's bookkeeping happens even if one of them fails."""
        nonlocal failure, stopping
        try:
            dispatch(event)
        except BrokenPipeError as error:  # stdout closed under a JSON consumer: stop, then report it
            if failure is None:
                failure = error
            if not stopping:
                stopping = True
                stop_running()
        finally:
            settle(event)

    try:
        for task in by_name.values():
            handle(TaskQueued(task.name, task.kind))
        while True:
            if interrupt.is_set() and not result.interrupted:
                result.interrupted = stopping = True
                stop_running()
            while not stopping and ready.has_ready() and len(running) < limit():
                task = ready.pop()
                try:
                    reasons = _check(task)
                except Exception as error:  # noqa: BLE001 - a broken check fails its task, not the run
                    handle(TaskFailed(task.name, task.kind, reason=f"up-to-date check failed: {error}"))
                    continue
                if reasons == []:
                    handle(TaskFinished(task.name, task.kind, cached=True))
                    continue
                context = TaskContext(task.name, events.put, task.kind)
                context.priority = ready.priority(task.key)
                thread = threading.Thread(target=_work, args=(task, context, tuple(reasons or ())),
                                          name=f"roc-worker-{task.key}")
                thread.start()
                threads.append(thread)
                running[task.key] = context
            if not running:
                break
            try:
                event = events.get(timeout=TICK_SECONDS)
            except queue.Empty:
                event = Tick("")
            handle(event)
    finally:
        for thread in threads:
            thread.join()
        while not events.empty():  # events emitted by the last workers while shutting down
            handle(events.get())
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    done = set(result.finished) | set(result.failed) | set(result.aborted) | set(result.skipped)
    result.not_started = [n for n in by_name if n not in done]
    handle(RunFinished("", kind, interrupted=result.interrupted, not_started=tuple(result.not_started)))
    if failure is not None:
        raise failure
    return result
