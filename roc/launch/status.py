"""A running ``roc launch``'s status and control, for ``roc tui``: a private Unix socket per run in
roc's runtime directory (``launch-<pid>.sock``, mode 0600), JSON lines in and out, one request a line:

- ``{"method": "status"}`` -> ``{"title", "pid", "log_directory", "restartable", "processes": [{name, host,
  pid, state, detail, restarts, last_line, code}]}`` (``restartable``: its processes can be started again, a
  roc.toml system's; a launch file's cannot; ``host``: the SSH destination of a process on another host, its
  pid that of its ssh client here);
- ``{"method": "stop", "process": NAME}``, ``{"method": "restart", "process": NAME}`` -> ``{"ok": true}`` or
  ``{"error": MESSAGE}``.

The output of each process is its log file (roc/launch/logs.py), read by the client. The server runs on
a thread of the ``roc launch`` process (``serve``); ``runs`` and ``RunStatus`` are the client.
Stdlib only: neither side loads rclpy or the launch library.
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, Protocol

from roc.errors import RocError

FOLLOW_SECONDS = 0.25


def socket_directory() -> Path:
    from roc.ros.client import runtime_dir

    return runtime_dir()


class Control(Protocol):
    restartable: bool

    def stop(self, process: str) -> None: ...

    def restart(self, process: str) -> None: ...


class SupervisorControl:
    """Stop or restart one process of a roc.toml system (roc/launch/supervisor.py): stopped as the
    whole run stops its processes (SIGINT, SIGTERM, SIGKILL), on purpose (no respawn, no failure of the
    run); restarted once its watcher has ended."""

    restartable = True

    def __init__(self, supervisor, system) -> None:
        self.supervisor = supervisor
        self.specs = {spec.label: spec for spec in system.processes}

    def _process(self, name: str):
        with self.supervisor._lock:
            process = self.supervisor._running.get(name)
        if process is None:
            raise RocError(f"{name} is not running")
        return process

    def stop(self, process: str) -> None:
        running = self._process(process)
        self.supervisor.monitor.stop_asked.add(process)
        self.supervisor._stop_one(process, running)

    def restart(self, process: str) -> None:
        if process not in self.specs:
            raise RocError(f"no process {process}")
        with contextlib.suppress(RocError):
            self.stop(process)
        for watcher in [t for t in self.supervisor._watchers if t.name == f"roc-{process}"]:
            watcher.join(timeout=15)
        self.supervisor.start(self.specs[process])


class SignalControl:
    """Stop one process the launch library started (SIGINT to its process, as the library stops it; its
    exit is a stop, as ros2 launch's run goes on when a process is stopped from outside); the library
    cannot start one again on request."""

    restartable = False

    def __init__(self, monitor) -> None:
        self.monitor = monitor

    def stop(self, process: str) -> None:
        row = next((r for r in self.monitor.snapshot() if r.name == process and r.state == "running"), None)
        if row is None or row.pid is None:
            raise RocError(f"{process} is not running")
        self.monitor.stop_asked.add(process)
        os.kill(row.pid, 2)

    def restart(self, process: str) -> None:
        raise RocError("the launch library started it and cannot start it again on request: stop it, or "
                       "declare the system in roc.toml")


class StatusServer:
    def __init__(self, running, control: Control) -> None:
        self.running, self.control = running, control
        self.path = socket_directory() / f"launch-{os.getpid()}.sock"
        self.path.unlink(missing_ok=True)
        self.listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        old_umask = os.umask(0o177)
        try:
            self.listener.bind(str(self.path))
        finally:
            os.umask(old_umask)
        self.listener.listen(8)
        self.listener.settimeout(0.5)
        self._closed = threading.Event()
        threading.Thread(target=self._serve, name="roc-launch-status", daemon=True).start()

    def _serve(self) -> None:
        while not self._closed.is_set():
            try:
                conn, _ = self.listener.accept()
            except (TimeoutError, OSError):
                continue
            threading.Thread(target=self._client, args=(conn,), daemon=True).start()

    def _client(self, conn: socket.socket) -> None:
        with conn, conn.makefile("r", encoding="utf-8") as reader:
            for line in reader:
                try:
                    answer = self.answer(json.loads(line))
                except (ValueError, AttributeError, KeyError):
                    answer = {"error": "a request is a JSON object with a 'method'"}
                except RocError as error:
                    answer = {"error": str(error)}
                try:
                    conn.sendall((json.dumps(answer) + "\n").encode())
                except OSError:
                    return

    def answer(self, request: dict[str, Any]) -> dict[str, Any]:
        method = request["method"]
        if method == "status":
            monitor = self.running.monitor
            return {"title": self.running.options.title, "pid": os.getpid(),
                    "log_directory": str(self.running.log_directory) if self.running.log_directory else None,
                    "restartable": self.control.restartable,
                    "processes": [{"name": r.name, "host": r.host or None, "pid": r.pid, "state": r.state,
                                   "detail": r.detail,
                                   "restarts": r.restarts, "last_line": r.last_line, "code": r.code}
                                  for r in monitor.snapshot()]}
        if method in ("stop", "restart"):
            threading.Thread(target=self._control, args=(method, request["process"]), daemon=True).start()
            return {"ok": True}
        raise RocError(f"unknown request '{method}'")

    def _control(self, method: str, process: str) -> None:
        try:
            getattr(self.control, method)(process)
            self.running.monitor.note(f"[INFO] [roc]: {process}: {method} asked by roc tui")
        except (RocError, OSError) as error:
            self.running.monitor.note(f"[ERROR] [roc]: {process}: {method}: {error}")

    def close(self) -> None:
        self._closed.set()
        self.listener.close()
        self.path.unlink(missing_ok=True)


def serve(running, control: Control) -> StatusServer | None:
    """The run's status socket, or None when it cannot be made (roc launch runs on without it)."""
    try:
        return StatusServer(running, control)
    except (OSError, RocError):
        return None


class RunStatus:
    """A client of one run's socket."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def request(self, method: str, **params: Any) -> dict[str, Any]:
        with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as client:
            client.settimeout(5)
            client.connect(str(self.path))
            client.sendall((json.dumps({"method": method, **params}) + "\n").encode())
            with client.makefile("r", encoding="utf-8") as reader:
                answer = json.loads(reader.readline() or "{}")
        if "error" in answer:
            raise RocError(answer["error"])
        return answer

    def follow(self, process: str, stop: Callable[[], bool]) -> Iterator[list[str]]:
        """The lines of the process's log file, those written so far first, until ``stop()``."""
        from roc.launch.logs import file_name

        directory = self.request("status").get("log_directory")
        if not directory:
            raise RocError("this run keeps no logs (started with --log-base none?)")
        path = Path(directory) / f"{file_name(process)}.log"
        offset, partial = 0, ""
        while not stop():
            if path.exists():
                with path.open("r", errors="replace") as log:
                    log.seek(offset)
                    text = log.read()
                    offset = log.tell()
                lines = (partial + text).split("\n")
                partial = lines.pop()
                if lines:
                    yield lines
            time.sleep(FOLLOW_SECONDS)


def runs() -> list[tuple[RunStatus, dict[str, Any]]]:
    """Each ``roc launch`` running on this host for this user, with its status (a dead socket removed)."""
    found = []
    for path in sorted(socket_directory().glob("launch-*.sock")):
        status = RunStatus(path)
        try:
            found.append((status, status.request("status")))
        except ConnectionRefusedError:
            path.unlink(missing_ok=True)
        except (OSError, RocError, ValueError):
            continue
    return found
