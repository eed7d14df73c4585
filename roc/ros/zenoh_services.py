"""Services across a Zenoh link (roc.ros.zenoh_link): the side with the server offers it as a Zenoh
queryable on ``roc/service/NAME``; the far side serves the same name and type in its own domain and
sends each request (serialised CDR) as a Zenoh query, answering with the reply.

rclpy sends a response when the service callback returns, so the far side's callback waits for the
query's reply: its server has a node of its own, spun by a multi-threaded executor, as the domain
bridge's ServiceLink, so a slow call holds one worker thread rather than the link's topics. The
offering side answers each query in a worker thread, which waits for the local server.
"""

from __future__ import annotations

import threading
from collections import deque
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import zenoh
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.serialization import deserialize_message, serialize_message

from roc.ros.graph import Graph
from roc.ros.types import service_class

SERVICE_PREFIX = "roc/service"
WORKER_THREADS = 8
CALL_SECONDS = 30.0  # a call's longest wait for the far server's response


class ServiceOffer:
    """A local server's service offered to the Zenoh peers."""

    def __init__(self, session: zenoh.Session, graph: Graph, name: str, type_name: str,
                 errors: deque[str]) -> None:
        self.name, self.count, self.errors = name, 0, errors
        self._cls = service_class(type_name)
        self._client = graph.node.create_client(self._cls, name)
        self._workers = ThreadPoolExecutor(WORKER_THREADS, thread_name_prefix="roc-zenoh-service")
        self._queryable = session.declare_queryable(
            f"{SERVICE_PREFIX}{name}", lambda query: self._workers.submit(self._answer, query), complete=True)

    def _answer(self, query: zenoh.Query) -> None:
        request = deserialize_message(query.payload.to_bytes(), self._cls.Request)
        done = threading.Event()
        future = self._client.call_async(request)
        future.add_done_callback(lambda _future: done.set())
        if not done.wait(CALL_SECONDS):
            self.errors.append(f"{self.name}: the server did not answer within {CALL_SECONDS:g} s")
            query.reply_err(b"no response")
            return
        self.count += 1
        query.reply(f"{SERVICE_PREFIX}{self.name}", serialize_message(future.result()))

    def close(self) -> None:
        self._queryable.undeclare()
        self._workers.shutdown(wait=False, cancel_futures=True)


class ServiceProxy:
    """A far side's service served in the local domain, each call a Zenoh query."""

    def __init__(self, session: zenoh.Session, graph: Graph, name: str, type_name: str, node_name: str,
                 errors: deque[str]) -> None:
        self.name, self.count, self.errors = name, 0, errors
        self._session = session
        self._cls = service_class(type_name)
        self._node = Node(node_name, context=graph.context, start_parameter_services=False, enable_rosout=False)
        self._node.create_service(self._cls, name, self._serve, callback_group=ReentrantCallbackGroup())
        self._executor = MultiThreadedExecutor(num_threads=WORKER_THREADS, context=graph.context)
        self._executor.add_node(self._node)
        self._spinner = threading.Thread(target=self._spin, daemon=True)
        self._spinner.start()

    def _spin(self) -> None:
        try:
            self._executor.spin()
        except Exception:  # noqa: BLE001 - the context was shut down under it
            pass

    def _serve(self, request: Any, response: Any) -> Any:
        """The far server's response; ``response`` (empty) when none came, with an error for ``errors``."""
        replies = self._session.get(f"{SERVICE_PREFIX}{self.name}", payload=serialize_message(request),
                                    timeout=CALL_SECONDS)
        for reply in replies:
            if reply.ok is not None:
                self.count += 1
                return deserialize_message(reply.ok.payload.to_bytes(), self._cls.Response)
        self.errors.append(f"{self.name}: the far side's server did not answer; the caller got an empty response")
        return response

    def close(self) -> None:
        self._executor.shutdown(timeout_sec=1)
        self._node.destroy_node()
