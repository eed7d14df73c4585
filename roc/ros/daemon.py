"""The roc daemon: one warm graph participant per user and discovery environment, answering JSON-line
requests on a Unix socket (mode 0600). Started by roc.ros.client.spawn_daemon, which binds the
socket and hands it over: ``python -m roc.ros.daemon SOCKET FD``. The protocol is in docs/daemon.md.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import signal
import socket
import sys
import threading
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from roc import __version__
from roc.errors import RocError
from roc.ros.protocol import discovery_environment

# An idle daemon exits after this long without a request (a scan of many domains leaves no daemons
# behind for long); a stream's lines count as requests. ROC_DAEMON_IDLE_SECONDS changes it.
DEFAULT_IDLE_SECONDS = 300.0


def idle_seconds(environment: Mapping[str, str] = os.environ) -> float:
    """ROC_DAEMON_IDLE_SECONDS, or the default when it is unset or not a positive number."""
    try:
        value = float(environment.get("ROC_DAEMON_IDLE_SECONDS") or DEFAULT_IDLE_SECONDS)
    except ValueError:
        return DEFAULT_IDLE_SECONDS
    return value if value > 0 else DEFAULT_IDLE_SECONDS


IDLE_SECONDS = idle_seconds()


class Daemon:
    def __init__(self, path: Path):
        self.path = path
        self.last_request = time.monotonic()
        self.stopping = threading.Event()
        self.created = threading.Event()  # the graph participant exists
        self.ready = threading.Event()  # ... and has had its discovery period
        self.graph: Any = None  # the roc.ros.graph.Graph, once created (imported then: rclpy is slow to load)
        self.started = time.time()

    def serve(self, listener: socket.socket) -> None:
        """Serve on ``listener``, bound at ``self.path`` and listening (roc.ros.client.spawn_daemon)."""
        self._inode = self.path.stat().st_ino
        listener.settimeout(0.5)
        threading.Thread(target=self._discover, daemon=True).start()
        try:
            while not self.stopping.is_set():
                if time.monotonic() - self.last_request > IDLE_SECONDS:
                    break
                try:
                    conn, _ = listener.accept()
                except TimeoutError:
                    continue
                threading.Thread(target=self._client, args=(conn,), daemon=True).start()
        finally:
            listener.close()
            # Only remove the socket if it is still ours (a replacement may have bound the path).
            try:
                if self.path.stat().st_ino == self._inode:
                    self.path.unlink()
            except FileNotFoundError:
                pass
            if self.graph is not None:
                self.graph.close()

    def _discover(self) -> None:
        from roc.ros.graph import Graph

        self.graph = Graph()
        self.created.set()
        self.graph.wait_for_discovery()
        self.ready.set()

    def _client(self, conn: socket.socket) -> None:
        with conn, conn.makefile("r", encoding="utf-8") as reader, contextlib.suppress(OSError):
            # OSError: the client went away (a broken pipe; or reset, when it closed with answers unread)
            for line in reader:
                self.last_request = time.monotonic()
                try:
                    request = json.loads(line)
                    request_id = request.get("id")
                except (json.JSONDecodeError, AttributeError):
                    request, request_id = {}, None
                # Closed as soon as the client is gone, so a stream's endpoint goes with it.
                with contextlib.closing(self._answer(request)) as responses:
                    for response in responses:
                        response["id"] = request_id
                        conn.sendall((json.dumps(response) + "\n").encode())
                        self.last_request = time.monotonic()
                if request.get("method") == "shutdown":
                    return

    def _answer(self, request: dict[str, Any]):
        """The response lines of one request; the last carries ``final: true``. Streaming requests
        (roc.ros.dataplane) yield ``{"event": ...}`` lines before it."""
        method = request.get("method")
        try:
            if method == "hello":
                result = {"version": __version__, "pid": os.getpid(), "environment": discovery_environment(),
                          "started": self.started, "ready": self.ready.is_set(), "socket": str(self.path),
                          "idle_seconds": IDLE_SECONDS}
            elif method == "shutdown":
                self.stopping.set()
                result = {"stopping": True}
            elif not isinstance(method, str):
                raise RocError("a request needs a 'method'")
            else:
                params = request.get("params") or {}
                # a stream that waits for what it needs (frame echo's tf) may ask to start before the
                # discovery period: its subscriptions match publishers as they are found
                if not (self.created if params.get("early") else self.ready).wait(30):
                    raise RocError("the daemon's graph participant did not start")
                from roc.ros.streams import STREAMS

                if method in STREAMS:
                    yield from STREAMS[method](self.graph, params)
                    result = None
                else:
                    result = self.graph.handle(method, params)
            yield {"final": True, "result": result}
        except RocError as error:
            yield {"final": True, "error": {"kind": type(error).__name__, "message": str(error),
                                            "exit_code": error.exit_code}}
        except Exception as error:  # noqa: BLE001 - the daemon outlives a bad request
            yield {"final": True, "error": {"kind": "internal", "message": f"{type(error).__name__}: {error}"}}


def main() -> None:
    from roc.rclpy_guard import guard_rclpy_import

    guard_rclpy_import()  # as every roc process: rclpy loads as the client's did (roc.rclpy_guard)
    path, listener_fd = Path(sys.argv[1]), int(sys.argv[2])
    # stderr is the daemon's log (roc.ros.client.spawn_daemon)
    logging.basicConfig(level=logging.WARNING, format="%(asctime)s %(name)s: %(message)s")
    daemon = Daemon(path)
    signal.signal(signal.SIGTERM, lambda *_: daemon.stopping.set())
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGHUP, signal.SIG_IGN)  # it outlives the terminal that started it
    os.chdir("/")
    daemon.serve(socket.socket(fileno=listener_fd))


if __name__ == "__main__":
    main()
