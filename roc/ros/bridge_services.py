"""One bridged service: a server in the destination domain whose every request is sent to the source
domain's server, and whose response is that server's.

rclpy sends a service's response when its callback returns, so the callback waits for the forwarded
call. The server has a node of its own, spun by a multi-threaded executor, so a slow call holds one
worker thread rather than the bridge's topics, and several calls can be in flight.
"""

from __future__ import annotations

import threading
from collections import deque
from typing import Any

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node

from roc.ros.types import service_class

WORKER_THREADS = 8
WAIT_FOR_SERVER_SECONDS = 5.0


class ServiceLink:
    def __init__(self, name: str, target: str, type_name: str, source, destination, node_name: str) -> None:
        """``source``/``destination``: the ``Graph`` of each domain (the source one has the real server)."""
        self.name = name
        self.count = 0
        self.errors: deque[str] = deque()
        self._closed = threading.Event()
        cls = service_class(type_name)
        self._client = source.node.create_client(cls, name)
        self._node = Node(node_name, context=destination.context, start_parameter_services=False,
                          enable_rosout=False)
        self._node.create_service(cls, target, self._serve, callback_group=ReentrantCallbackGroup())
        self._executor = MultiThreadedExecutor(num_threads=WORKER_THREADS, context=destination.context)
        self._executor.add_node(self._node)
        self._spinner = threading.Thread(target=self._spin, daemon=True)
        self._spinner.start()

    def _spin(self) -> None:
        try:
            self._executor.spin()
        except Exception:  # noqa: BLE001 - the context was shut down under it
            pass

    def _serve(self, request: Any, response: Any) -> Any:
        """The source server's response; ``response`` (empty) only when there is none, with an error
        for ``errors``."""
        if not self._client.wait_for_service(timeout_sec=WAIT_FOR_SERVER_SECONDS):
            self.errors.append(f"{self.name}: no server answered within {WAIT_FOR_SERVER_SECONDS:g} s; "
                               "the caller got an empty response")
            return response
        done = threading.Event()
        future = self._client.call_async(request)
        future.add_done_callback(lambda _future: done.set())
        while not done.wait(0.1):
            if self._closed.is_set():
                return response
        self.count += 1
        return future.result()

    def close(self) -> None:
        self._closed.set()
        self._executor.shutdown(timeout_sec=1)
        self._node.destroy_node()
