"""roc's own process supervisor, for the systems of roc.toml: starts a process (in a process group of its
own in roc's session: only roc signals it, and it shares the terminal session's CPU share as under ros2
launch; forked from a warm interpreter when it can, roc/launch/warm_start.py), reads its output into the
monitor, restarts it when it has ``respawn``, and stops every process as ros2 launch does: SIGINT, then
SIGTERM after 5 s, then SIGKILL after 5 s more."""

from __future__ import annotations

import os
import signal
import subprocess
import threading
from collections.abc import Callable

from roc.engine.process import TaskError
from roc.launch.monitor import Monitor
from roc.launch.remote import RemoteProcess
from roc.launch.system import HostSpec, ProcessSpec
from roc.launch.warm_start import ForkedProcess, WarmStart

Process = subprocess.Popen | ForkedProcess | RemoteProcess

SIGTERM_AFTER = 5.0
SIGKILL_AFTER = 5.0


def command(spec: ProcessSpec) -> list[str]:
    """The process's command line: its package's executable, its arguments, then its ROS arguments."""
    from roc.ament_index import find_executable

    return [str(find_executable(spec.package, spec.executable)), *spec.arguments, *spec.ros_arguments()]


def _command_line(process: Process) -> list[str]:
    """The command line a process runs (on its host)."""
    args = process.args
    return [str(word) for word in args] if isinstance(args, list | tuple) else [str(args)]


class Supervisor:
    def __init__(self, monitor: Monitor, environment: Callable[[dict[str, str]], dict[str, str]],
                 record: Callable[[int], None]):
        self.monitor = monitor
        self.warm: WarmStart | None = None  # the run's fork servers, if it forks its Python processes
        self.environment = environment  # a process's extra variables -> its whole environment
        self.record = record  # tells the orphan guard about each process started
        self.hosts: dict[str, HostSpec] = {}  # where the processes with a host run (roc/launch/remote.py)
        self.token = ""  # the run's token (the orphan guard's), made unique per remote process start
        self._remote_starts = 0
        self.stopping = monitor.stopping  # set: no more restarts, and exits are no failures
        self.failed: list[str] = []  # processes that ended with an error (and are not restarted)
        self._lock = threading.Lock()
        self._running: dict[str, Process] = {}
        self._watchers: list[threading.Thread] = []
        self._changed = threading.Condition(self._lock)

    def start(self, spec: ProcessSpec) -> None:
        """Start the process (raises TaskError when it cannot); a thread watches it from then on."""
        process = self._spawn(spec)
        watcher = threading.Thread(target=self._watch, args=(spec, process), name=f"roc-{spec.label}", daemon=True)
        with self._lock:
            self._watchers.append(watcher)
        watcher.start()

    def _spawn(self, spec: ProcessSpec) -> Process:
        process = self._spawn_remote(spec) if spec.host else self._spawn_local(spec)
        with self._lock:
            self._running[spec.label] = process
            self._changed.notify_all()
        self.monitor.started(spec.label, process.pid, _command_line(process), warm=isinstance(process, ForkedProcess))
        return process

    def _spawn_local(self, spec: ProcessSpec) -> Process:
        line = command(spec)
        env = self.environment(spec.env)
        process: Process | None = None
        if self.warm is not None and spec.warm_start:
            process = self.warm.popen(line, env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                      stderr=subprocess.STDOUT)
        if process is None:
            try:
                process = subprocess.Popen(line, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                           stderr=subprocess.STDOUT, process_group=0, env=env)
            except OSError as error:
                raise TaskError(f"cannot run '{line[0]}': {error.strerror}") from None
        self.record(process.pid)
        return process

    def _spawn_remote(self, spec: ProcessSpec) -> RemoteProcess:
        label = f"{spec.host}:{spec.label}"
        self._remote_starts += 1  # a token per start: the guard of a lost session must not stop its successor
        token = f"{self.token}@{spec.host}/{spec.label}/{self._remote_starts}"
        process = RemoteProcess(self.hosts[spec.host], spec, token,
                                self.environment({}),
                                note=lambda text: self.monitor.note(f"[WARNING] [{label}]: {text}"),
                                usage=lambda cpu, rss: self.monitor.usage(spec.label, cpu, rss))
        self.record(process.ssh.pid)  # the orphan guard ends the session, and the guard there the process
        process.wait_started()
        return process

    def _watch(self, spec: ProcessSpec, process: Process) -> None:
        while True:
            assert process.stdout is not None
            while data := os.read(process.stdout.fileno(), 65536):
                self.monitor.output_text(spec.label, data.decode(errors="replace"))
            process.stdout.close()
            code = process.wait()
            self.monitor.exited(spec.label, process.pid, code, _command_line(process))
            asked = spec.label in self.monitor.stop_asked  # stopped on request: no respawn, no failure
            if not spec.respawn or asked or self.stopping.is_set() or self.stopping.wait(spec.respawn_delay):
                break
            try:
                process = self._spawn(spec)
            except TaskError as error:
                self.monitor.note(f"[ERROR] [{spec.label}]: {error}")
                break
        with self._lock:
            self._running.pop(spec.label, None)
            if code != 0 and not self.stopping.is_set() and spec.label not in self.monitor.stop_asked:
                self.failed.append(spec.label)
            self._changed.notify_all()

    def wait(self, stop: threading.Event) -> None:
        """Until every process has ended for good, or ``stop`` is set."""
        with self._lock:
            while self._running and not stop.is_set():
                self._changed.wait(timeout=0.5)

    def stop(self) -> None:
        """Stop every process (in parallel), and wait for their watchers."""
        self.stopping.set()
        with self._lock:
            running = list(self._running.items())
        stoppers = [threading.Thread(target=self._stop_one, args=item, daemon=True) for item in running]
        for thread in stoppers:
            thread.start()
        for thread in stoppers:
            thread.join()
        with self._lock:
            watchers = list(self._watchers)
        for watcher in watchers:
            watcher.join(timeout=SIGTERM_AFTER + SIGKILL_AFTER)

    def _stop_one(self, label: str, process: Process) -> None:
        for signum, grace in ((signal.SIGINT, SIGTERM_AFTER), (signal.SIGTERM, SIGKILL_AFTER),
                              (signal.SIGKILL, SIGKILL_AFTER)):
            if process.poll() is not None:
                return
            shown = self.monitor.shown(label)
            self.monitor.note(f"[INFO] [{shown}]: sending signal '{signal.Signals(signum).name}' to process[{shown}]")
            try:
                if isinstance(process, RemoteProcess):
                    process.send_signal(signum)  # to its group on its host
                else:
                    os.killpg(process.pid, signum)  # the process leads its own group: its children too
            except ProcessLookupError:
                return
            try:
                process.wait(timeout=grace)
                return
            except subprocess.TimeoutExpired:
                continue
