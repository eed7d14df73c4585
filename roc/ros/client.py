"""Graph queries from a verb: through the roc daemon (started on demand), or locally with ``--no-daemon``.

This module never imports rclpy: a query through a warm daemon costs a socket round trip, not
rclpy's import time. Modules only needed to start a daemon are imported when one is started. The
protocol is in docs/daemon.md.
"""

from __future__ import annotations

import fcntl
import json
import os
import socket
import sys
import threading
import time
import zlib
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from roc import __version__
from roc.errors import RocError
from roc.ros.protocol import Events, discovery_environment

REQUEST_TIMEOUT = float(os.environ.get("ROC_DAEMON_TIMEOUT", "30"))
START_TIMEOUT = 15.0


class DaemonError(RocError):
    """The daemon answered with an error (its message is for the user; its exit code is the one of
    the error the daemon raised: bad input is a usage error through the daemon too)."""

    def __init__(self, error: dict[str, Any]) -> None:
        super().__init__(error["message"])
        self.exit_code = error.get("exit_code", self.exit_code)


def daemon_key(env: dict[str, str] | None = None) -> str:
    """A short hash of the discovery environment and roc's version: one daemon per key. (A cheap
    checksum: the daemon's ``hello`` answer is compared in full, so a collision is caught.)"""
    text = json.dumps([__version__, discovery_environment(env)], sort_keys=True).encode()
    return f"{zlib.crc32(text):08x}{zlib.adler32(text):08x}"


# A Unix socket's path must fit in 107 bytes; the longest one roc binds is the daemon's staging name.
SOCKET_PATH_MAX = 107
LONGEST_SOCKET_NAME = len(".daemon-0123456789abcdef.sock.4194304")


def runtime_dir() -> Path:
    """A directory only this user can enter: $XDG_RUNTIME_DIR/roc, or /tmp/roc-UID when there is no
    such directory or its path is too long for a socket."""
    base = os.environ.get("XDG_RUNTIME_DIR")
    if base and Path(base).is_dir() and len(os.path.join(base, "roc")) + 1 + LONGEST_SOCKET_NAME <= SOCKET_PATH_MAX:
        path = Path(base) / "roc"
    else:
        import tempfile

        path = Path(tempfile.gettempdir()) / f"roc-{os.getuid()}"
    path.mkdir(mode=0o700, parents=True, exist_ok=True)
    if path.stat().st_uid != os.getuid() or path.stat().st_mode & 0o077:
        raise RocError(f"{path}: not private to this user (mode {path.stat().st_mode & 0o777:o}); remove it")
    return path


def socket_path(env: dict[str, str] | None = None) -> Path:
    return runtime_dir() / f"daemon-{daemon_key(env)}.sock"


class Connection:
    """One client connection: JSON lines out, JSON lines in."""

    def __init__(self, sock: socket.socket):
        self.sock = sock
        self.reader = sock.makefile("r", encoding="utf-8")
        self.next_id = 0

    def stream(self, method: str, params: dict[str, Any] | None = None,
               timeout: float = REQUEST_TIMEOUT) -> Events:
        """Send a request; yield each response line until the final one (``"final": true``)."""
        self.next_id += 1
        request = {"id": self.next_id, "method": method, "params": params or {}}
        self.sock.settimeout(timeout)
        try:
            self.sock.sendall((json.dumps(request) + "\n").encode())
            while True:
                line = self.reader.readline()
                if not line:
                    raise RocError("the roc daemon closed the connection; run 'roc daemon stop' and retry")
                response = json.loads(line)
                yield response
                if response.get("final"):
                    return
        except TimeoutError:
            raise RocError(f"the roc daemon did not answer '{method}' within {timeout:g} s") from None

    def request(self, method: str, params: dict[str, Any] | None = None, timeout: float = REQUEST_TIMEOUT) -> Any:
        final = list(self.stream(method, params, timeout))[-1]
        if "error" in final:
            raise DaemonError(final["error"])
        return final.get("result")

    def close(self) -> None:
        self.reader.close()
        self.sock.close()


def connect(path: Path | None = None) -> Connection | None:
    """A connection to the running daemon, or None (a dead socket file is removed)."""
    path = path or socket_path()
    if not path.exists():
        return None
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    try:
        sock.connect(str(path))
    except (ConnectionRefusedError, FileNotFoundError):
        sock.close()
        path.unlink(missing_ok=True)
        return None
    return Connection(sock)


@contextmanager
def _start_lock(path: Path):
    with open(path.with_suffix(".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        yield


def _usable(connection: Connection, timeout: float = 10) -> bool:
    """The daemon is of this roc version and serves this discovery environment; else it is stopped."""
    hello = connection.request("hello", timeout=timeout)
    if hello.get("version") == __version__ and hello.get("environment") == discovery_environment():
        return True
    try:
        connection.request("shutdown", timeout=5)
    except RocError:
        pass
    connection.close()
    return False


def running_daemon(path: Path | None = None, hello_timeout: float = 10) -> Connection | None:
    """A connection to this environment's daemon when one of this roc version runs, else None (one of
    another version or environment is told to stop)."""
    connection = connect(path or socket_path())
    if connection is None:
        return None
    try:
        usable = _usable(connection, hello_timeout)
    except BaseException:
        connection.close()
        raise
    return connection if usable else None


def spawn_daemon() -> None:
    """Start this environment's daemon unless one runs, without waiting for it (as ``ros2`` does). The
    socket is bound, listening, here and handed to the daemon, so the path takes connections from
    now on: a client's requests wait in its backlog until the daemon serves them.

    The daemon runs detached in a process group of its own, so the terminal's Ctrl+C and hang-up do
    not reach it, but in the caller's session. A session of its own is a scheduling group of its own
    on Linux (autogroup): on a busy machine the daemon then went without CPU for up to 3.6 s at a
    time, and echo lost 10-35 k of 50 k messages at 5 kHz where it now loses 0-2.5 k
    (bench/dataplane_bench.py)."""
    from roc.distribution import refuse_mix
    from roc.middleware import process_environment

    refuse_mix()  # the daemon, started with this environment, would load two distributions' libraries
    path = socket_path()
    with _start_lock(path):
        connection = running_daemon(path)
        if connection is not None:
            connection.close()
            return
        _wait_gone(path)
        listener = _listen(path)
        import subprocess

        try:
            with open(path.with_suffix(".log"), "ab") as log:
                # not one of a roc launch's processes, even when one of them starts it (roc/launch/guard.py's token)
                env = {name: value for name, value in os.environ.items() if name != "ROC_LAUNCH_ID"}
                env = process_environment(env)  # the middleware RMW_IMPLEMENTATION names (roc/middleware.py)
                subprocess.Popen([sys.executable, "-m", "roc.ros.daemon", str(path), str(listener.fileno())],
                                 stdin=subprocess.DEVNULL, stdout=log, stderr=log, process_group=0,
                                 pass_fds=(listener.fileno(),), env=env)
        except BaseException:
            path.unlink(missing_ok=True)
            raise
        finally:
            listener.close()


def _listen(path: Path) -> socket.socket:
    """A socket listening at ``path``, mode 0600. Bound under a temporary name and renamed into place,
    so a client never finds the path refusing connections (it would take it for a dead daemon's
    socket and remove it)."""
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    staging = path.with_name(f".{path.name}.{os.getpid()}")
    staging.unlink(missing_ok=True)
    old_umask = os.umask(0o177)
    try:
        listener.bind(str(staging))
    finally:
        os.umask(old_umask)
    listener.listen(64)
    os.replace(staging, path)
    return listener


def start_daemon() -> Connection:
    """A connection to this environment's daemon, started if none runs; it answers once the daemon
    serves (its first graph answer waits for its discovery)."""
    connection = running_daemon()
    if connection is not None:
        return connection
    spawn_daemon()
    try:
        connection = running_daemon(hello_timeout=START_TIMEOUT)
    except RocError:
        connection = None
    if connection is None:
        log = socket_path().with_suffix(".log")
        raise RocError(f"the roc daemon did not start within {START_TIMEOUT:g} s; see {log}")
    return connection


def _wait_gone(path: Path, timeout: float = 5.0) -> None:
    """Give a daemon that was told to stop the time to remove its socket."""
    deadline = time.monotonic() + timeout
    while path.exists() and time.monotonic() < deadline:
        if connect(path) is None:
            return
        time.sleep(0.05)


def stop_daemon(path: Path | None = None) -> bool:
    """Stop this environment's daemon (or the one at ``path``); False when none was running."""
    path = path or socket_path()
    connection = connect(path)
    if connection is None:
        return False
    try:
        connection.request("shutdown", timeout=5)
    finally:
        connection.close()
    _wait_gone(path)
    return True


def stop_all_daemons() -> int:
    """Stop every roc daemon of this user, whatever its discovery environment; how many were running."""
    return sum(stop_daemon(path) for path in sorted(runtime_dir().glob("daemon-*.sock")))


def daemon_status(path: Path | None = None) -> dict[str, Any] | None:
    """The ``hello`` of this environment's daemon (or the one at ``path``), None when none runs."""
    connection = connect(path or socket_path())
    if connection is None:
        return None
    try:
        return connection.request("hello", timeout=5)
    finally:
        connection.close()


def all_daemon_statuses() -> list[dict[str, Any]]:
    """The ``hello`` of every roc daemon of this user, whatever its discovery environment (a daemon
    that does not answer is left out; a dead socket is removed)."""
    statuses = []
    for path in sorted(runtime_dir().glob("daemon-*.sock")):
        try:
            status = daemon_status(path)
        except (RocError, OSError, ValueError):
            continue
        if status is not None:
            statuses.append(status)
    return sorted(statuses, key=lambda status: status.get("started", 0))


def query_running_daemon(method: str, params: dict[str, Any] | None = None) -> Any:
    """Answer a graph request through this environment's daemon if one is running (never starting one:
    for lookups that are worth a warm graph's answer but not a cold discovery's wait); None when none runs."""
    connection = running_daemon()
    if connection is None:
        return None
    try:
        return connection.request(method, params or {})
    finally:
        connection.close()


def query(method: str, params: dict[str, Any] | None = None, *, use_daemon: bool = True,
          spin_time: float | None = None) -> Any:
    """Answer a graph request (on a Session: through the running daemon, else in this process)."""
    session = Session(use_daemon, spin_time)
    try:
        return session.query(method, params)
    finally:
        session.close()


def stream(method: str, params: dict[str, Any], *, use_daemon: bool = True, heartbeats: bool = False,
           **local: Any) -> Events:
    """The events of a streaming request (roc.ros.dataplane), in the daemon unless ``use_daemon`` is
    false (``local``: options of roc.ros.in_process.stream), or in this process when the daemon
    cannot import the type; closing the iterator (or Ctrl+C) ends the stream and removes its endpoint.
    ``heartbeats``: pass on the heartbeat events too (at least every 0.5 s, to act between events)."""
    skipped = () if heartbeats else ("heartbeat",)
    if not use_daemon:
        events = _in_process().stream(method, params, **local)
        yield from (event for event in events if event.get("event") not in skipped)
        return
    connection = start_daemon()
    try:
        started = False
        for response in connection.stream(method, params):
            error = response.get("error")
            if error and error.get("kind") == "UnknownTypeError" and not started:
                break  # a type the daemon's environment lacks (an overlay sourced since it started)
            if error:
                raise DaemonError(error)
            if response.get("event") is not None and response["event"] not in skipped:
                started = True
                yield response
        else:
            return
    finally:
        connection.close()
    yield from stream(method, params, use_daemon=False, heartbeats=heartbeats, **local)


class Session:
    """Queries and streams on one participant: the running daemon's, or else one of this process,
    discovered once (see roc.ros.graph.Graph); then the daemon is started as the session closes, for
    the next verb. So a cold verb is no slower than with ``--no-daemon``, which never starts one (as
    ``ros2`` does). A ``long_lived`` session (a launch's probes, the TUI) starts the daemon and
    waits for it instead. Thread-safe."""

    def __init__(self, use_daemon: bool = True, spin_time: float | None = None, long_lived: bool = False):
        self.graph = None  # None: through the daemon
        self.start_daemon_on_close = False
        self._lock = threading.Lock()
        # the connection that found the daemon, for the first query (a one-shot verb's only one)
        self._first: Connection | None = None
        if use_daemon:
            self._first = start_daemon() if long_lived else running_daemon()
            if self._first is not None:
                return
        # fetching what this process's participant needs from the others while rclpy loads (early_probe);
        # a one-shot verb's participant only asks; a long-lived one's streams may publish (the TUI's)
        from roc.ros.discovery import early_probe

        probe = early_probe()
        self.graph = _in_process().discovered_graph(spin_time, asks_only=not long_lived, probe=probe)
        self.start_daemon_on_close = use_daemon

    def query(self, method: str, params: dict[str, Any] | None = None) -> Any:
        if self.graph is not None:
            return self.graph.handle(method, params or {})
        with self._lock:
            connection, self._first = self._first, None
        connection = connection or start_daemon()
        try:
            return connection.request(method, params or {})
        finally:
            connection.close()

    def stream(self, method: str, params: dict[str, Any], heartbeats: bool = False) -> Events:
        if self.graph is None:
            yield from stream(method, params, heartbeats=heartbeats)
            return
        events = _in_process().stream_on(self.graph, method, params)
        yield from (e for e in events if heartbeats or e.get("event") != "heartbeat")

    def close(self) -> None:
        with self._lock:
            connection, self._first = self._first, None
        if connection is not None:
            connection.close()
        if self.graph is not None:
            self.graph.close()
        if self.start_daemon_on_close:
            self.start_daemon_on_close = False
            spawn_daemon()


def _in_process():
    """The in-process fallback (roc.ros.in_process, which imports rclpy): the client's one way to the
    rclpy graph, for ``--no-daemon``, ``Session(use_daemon=False)`` and types the daemon lacks."""
    from roc.ros import in_process

    return in_process
