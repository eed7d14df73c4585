"""Running a task's commands: output streamed as events, the whole process tree stoppable."""

from __future__ import annotations

import os
import threading
from collections import namedtuple
from collections.abc import Callable, Mapping, Sequence

from roc.engine.events import CommandEnded, CommandStarted, Event, TaskOutput

TYPE_CHECKING = False  # subprocess and selectors are imported where a command runs: a no-op build runs none
if TYPE_CHECKING:
    import subprocess

STOP_GRACE_SECONDS = 3.0


class TaskError(Exception):
    """The task failed; the message says why (shown in the summary)."""


class TaskCancelled(Exception):
    """The task was stopped from outside (another task failed, or Ctrl+C)."""


class RanElsewhere(namedtuple("RanElsewhere", ("worker", "duration"))):
    """What an action returns when another machine did its work (a cluster worker): the worker's name
    and how long the work took there, which its TaskFinished event carries instead of the time here."""

    __slots__ = ()
    worker: str
    duration: float


def stop_process_tree(pid: int, grace: float = STOP_GRACE_SECONDS) -> None:
    """Terminate ``pid`` and all its descendants; kill what is still alive after ``grace`` seconds."""
    import psutil

    try:
        root = psutil.Process(pid)
        processes = [*root.children(recursive=True), root]
    except psutil.NoSuchProcess:
        return
    for process in processes:
        try:
            process.terminate()
        except psutil.NoSuchProcess:
            pass
    _, alive = psutil.wait_procs(processes, timeout=grace)
    for process in alive:
        try:
            process.kill()
        except psutil.NoSuchProcess:
            pass
    psutil.wait_procs(alive, timeout=grace)


class TaskContext:
    """What a task's action gets: a way to emit events and to run commands that can be stopped."""

    def __init__(self, name: str, emit: Callable[[Event], None], kind: str = "build"):
        self.name = name
        self.kind = kind
        self._emit = emit
        self._lock = threading.Lock()
        self._process: subprocess.Popen | None = None
        self.cancelled = False
        self.priority = 0.0  # how long a chain of work waits on this task (the ready queue's order)

    def emit(self, event: Event) -> None:
        self._emit(event)

    def cancel(self) -> None:
        """Stop the running command (if any) and every command this task would start."""
        with self._lock:
            self.cancelled = True
            process = self._process
        if process is not None and process.poll() is None:
            stop_process_tree(process.pid)

    def run(
        self,
        command: Sequence[str],
        cwd: str,
        env: Mapping[str, str],
        pass_fds: Sequence[int] = (),
    ) -> int:
        """Run ``command``, emitting its output; returns the exit code, raises TaskCancelled if cancelled."""
        import subprocess

        command = tuple(str(part) for part in command)
        with self._lock:
            if self.cancelled:
                raise TaskCancelled
            self.emit(CommandStarted(self.name, self.kind, command=command, cwd=str(cwd)))
            try:
                process = subprocess.Popen(
                    command, cwd=cwd, env=dict(env), stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                    stderr=subprocess.PIPE, pass_fds=tuple(pass_fds), start_new_session=True,
                )
            except OSError as error:
                raise TaskError(f"cannot run '{command[0]}': {error.strerror}") from None
            self._process = process
        self._pump(process)
        returncode = process.wait()
        with self._lock:
            self._process = None
            cancelled = self.cancelled
        self.emit(CommandEnded(self.name, self.kind, command=command, returncode=returncode))
        if cancelled:
            raise TaskCancelled
        return returncode

    def _pump(self, process: subprocess.Popen) -> None:
        import selectors

        assert process.stdout is not None and process.stderr is not None  # started with PIPE for both
        with selectors.DefaultSelector() as selector:
            selector.register(process.stdout, selectors.EVENT_READ, "stdout")
            selector.register(process.stderr, selectors.EVENT_READ, "stderr")
            open_streams = 2
            while open_streams:
                for key, _ in selector.select():
                    data = os.read(key.fd, 65536)
                    if not data:
                        selector.unregister(key.fileobj)
                        open_streams -= 1
                        continue
                    self.emit(TaskOutput(self.name, self.kind, stream=key.data, data=data))
        process.stdout.close()
        process.stderr.close()
