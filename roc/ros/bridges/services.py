"""Bridged services: a server in one domain whose every request is forwarded (to the source domain's
server, or across Zenoh) and whose response is the one that comes back.

rclpy sends a service's response when its callback returns, so the callback waits for the forwarded
call. The server has a node of its own, spun by a multi-threaded executor, so a slow call holds one
worker thread rather than the bridge's topics, and several calls can be in flight.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from typing import Any

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node

from roc.ros.types import service_class

WORKER_THREADS = 8
WAIT_FOR_SERVER_SECONDS = 5.0


def call(client, request: Any, seconds: float | None = None, closed: threading.Event | None = None) -> Any | None:
    """The response to ``request`` through an rclpy ``client`` (spun elsewhere); None when none came
    within ``seconds`` (None: no limit) or ``closed`` was set first."""
    done = threading.Event()
    future = client.call_async(request)
    future.add_done_callback(lambda _future: done.set())
    deadline = None if seconds is None else time.monotonic() + seconds
    while not done.wait(0.1):
        if (closed is not None and closed.is_set()) or (deadline is not None and time.monotonic() >= deadline):
            return None
    return future.result()


class ForwardingServer:
    """Serves ``name`` in ``graph``'s domain; ``forward`` gives each response (None: there is none, the
    caller gets an empty one and ``forward`` has said why in ``errors``)."""

    def __init__(self, graph, name: str, type_name: str, node_name: str, errors: deque[str] | None = None) -> None:
        self.name = name
        self.count = 0
        self.errors: deque[str] = deque() if errors is None else errors
        self.service_type = service_class(type_name)
        self._node = Node(node_name, context=graph.context, start_parameter_services=False, enable_rosout=False)
        self._node.create_service(self.service_type, name, self._serve, callback_group=ReentrantCallbackGroup())
        self._executor = MultiThreadedExecutor(num_threads=WORKER_THREADS, context=graph.context)
        self._executor.add_node(self._node)
        self._spinner = threading.Thread(target=self._spin, daemon=True)
        self._spinner.start()

    def _spin(self) -> None:
        try:
            self._executor.spin()
        except Exception:  # noqa: BLE001 - the context was shut down under it
            pass

    def forward(self, request: Any) -> Any | None:
        raise NotImplementedError

    def _serve(self, request: Any, response: Any) -> Any:
        answer = self.forward(request)
        if answer is None:
            return response
        self.count += 1
        return answer

    def close(self) -> None:
        self._executor.shutdown(timeout_sec=1)
        self._node.destroy_node()


class ServiceLink(ForwardingServer):
    """A source domain's service served as ``target`` in the destination domain."""

    def __init__(self, name: str, target: str, type_name: str, source, destination, node_name: str) -> None:
        """``source``/``destination``: the ``Graph`` of each domain (the source one has the real server)."""
        super().__init__(destination, target, type_name, node_name)
        self.name = name
        self._closed = threading.Event()
        self._client = source.node.create_client(self.service_type, name)

    def forward(self, request: Any) -> Any | None:
        if not self._client.wait_for_service(timeout_sec=WAIT_FOR_SERVER_SECONDS):
            self.errors.append(f"{self.name}: no server answered within {WAIT_FOR_SERVER_SECONDS:g} s; "
                               "the caller got an empty response")
            return None
        return call(self._client, request, closed=self._closed)

    def close(self) -> None:
        self._closed.set()
        super().close()
