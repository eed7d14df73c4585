"""Services across a Zenoh link (roc.ros.bridges.zenoh_link): the side with the server offers it as a Zenoh
queryable on ``roc/service/NAME``; the far side serves the same name and type in its own domain and
sends each request (serialised CDR) as a Zenoh query, answering with the reply.

rclpy sends a response when the service callback returns, so the far side's callback waits for the
query's reply: it is a ForwardingServer, as the domain bridge's ServiceLink. The
offering side answers each query in a worker thread, which waits for the local server.
"""

from __future__ import annotations

from collections import deque
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import zenoh
from rclpy.serialization import deserialize_message, serialize_message

from roc.ros.bridges.services import WORKER_THREADS, ForwardingServer, call
from roc.ros.graph import Graph
from roc.ros.types import service_class

SERVICE_PREFIX = "roc/service"
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
        payload = query.payload.to_bytes() if query.payload is not None else b""
        response = call(self._client, deserialize_message(payload, self._cls.Request), CALL_SECONDS)
        if response is None:
            self.errors.append(f"{self.name}: the server did not answer within {CALL_SECONDS:g} s")
            query.reply_err(b"no response")
            return
        self.count += 1
        query.reply(f"{SERVICE_PREFIX}{self.name}", serialize_message(response))

    def close(self) -> None:
        self._queryable.undeclare()
        self._workers.shutdown(wait=False, cancel_futures=True)


class ServiceProxy(ForwardingServer):
    """A far side's service served in the local domain, each call a Zenoh query."""

    def __init__(self, session: zenoh.Session, graph: Graph, name: str, type_name: str, node_name: str,
                 errors: deque[str]) -> None:
        self._session = session
        super().__init__(graph, name, type_name, node_name, errors)

    def forward(self, request: Any) -> Any | None:
        """The far server's response; None when none came."""
        replies = self._session.get(f"{SERVICE_PREFIX}{self.name}", payload=serialize_message(request),
                                    timeout=CALL_SECONDS)
        for reply in replies:
            if reply.ok is not None:
                return deserialize_message(reply.ok.payload.to_bytes(), self.service_type.Response)
        self.errors.append(f"{self.name}: the far side's server did not answer; the caller got an empty response")
        return None
