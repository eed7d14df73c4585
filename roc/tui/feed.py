"""The TUI's one way to the ROS graph: the roc daemon (roc.ros.client), never rclpy in this process.

Queries go through a ``Session``; streams go straight to the daemon's connection, without the
client's in-process fallback for types the daemon lacks (that fallback imports rclpy): such a topic
is left out of the rates instead.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any

from roc.errors import RocError
from roc.ros.client import DaemonError, Session, start_daemon

if TYPE_CHECKING:
    from concurrent.futures import Future

CALL_TIMEOUT = 5.0  # seconds for a node's service to answer, as roc's verbs wait
ENDPOINTS_SECONDS = 5.0


def counts_of(snapshot: dict[str, Any]) -> dict[str, tuple[int, int]]:
    """Each topic's publishers and subscribers, as a snapshot counts them."""
    return {topic["name"]: (topic["publishers"], topic["subscribers"]) for topic in snapshot["topics"]}


class Feed:
    """A lazily started daemon session, shared by every screen (thread-safe: each query and stream
    has a connection of its own)."""

    def __init__(self) -> None:
        self._session: Session | None = None
        self._lock = threading.Lock()
        self._first: Future | None = None
        self._endpoints: dict[str, dict[str, Any]] = {}  # topic -> its endpoints, as last asked for
        self._endpoints_due = 0.0  # time.monotonic() when they are asked for again

    def prefetch(self) -> None:
        """Ask for the first snapshot now, on a thread of its own: the daemon answers while the app's
        modules load (about as long as its answer takes), so that the first screen can show the graph."""
        from concurrent.futures import Future

        first: Future = Future()

        def ask() -> None:
            try:
                first.set_result(self.query("snapshot", {"endpoints": True}))
            except BaseException as error:  # noqa: BLE001 - raised again where the snapshot is taken
                first.set_exception(error)

        self._first = first
        threading.Thread(target=ask, name="roc-tui-prefetch", daemon=True).start()

    def session(self) -> Session:
        with self._lock:
            if self._session is None:
                self._session = Session(long_lived=True)
            return self._session

    def query(self, method: str, params: dict[str, Any] | None = None) -> Any:
        return self.session().query(method, params)

    def snapshot(self) -> dict[str, Any]:
        """Nodes, topics with their endpoints (for the diagnoses and the nodes' processes), services,
        actions (the first time, the prefetched answer, if any). The endpoints are asked for again when
        a topic's counts change and every ENDPOINTS_SECONDS, else the last ones are kept: asking for
        those of 200 topics every second cost the daemon 20 % of a core."""
        first, self._first = self._first, None
        if first is not None:
            return self._full(first.result())
        if time.monotonic() < self._endpoints_due:
            found = self.query("snapshot", {"endpoints": False})
            known = self._endpoints
            if counts_of(found) == {name: (len(ends["publishers"]), len(ends["subscribers"]))
                                    for name, ends in known.items()}:
                return {**found, "topics": [{**topic, "endpoints": known[topic["name"]]} for topic in found["topics"]]}
        return self._full(self.query("snapshot", {"endpoints": True}))

    def _full(self, snapshot: dict[str, Any]) -> dict[str, Any]:
        """Keep the endpoints of a snapshot asked for with them."""
        self._endpoints = {topic["name"]: topic["endpoints"] for topic in snapshot["topics"] if "endpoints" in topic}
        self._endpoints_due = time.monotonic() + ENDPOINTS_SECONDS
        return snapshot

    def stream(self, method: str, params: dict[str, Any], stop: Callable[[], bool]) -> Iterator[dict[str, Any]]:
        """The events of a daemon stream, heartbeats included, until it ends or ``stop()`` is true
        (checked at each event: the daemon sends a heartbeat at least every 0.5 s). An error ends it
        with DaemonError."""
        self.session()
        connection = start_daemon()
        try:
            for response in connection.stream(method, params):
                if stop():
                    return
                if "error" in response:
                    raise DaemonError(response["error"])
                if response.get("event") is not None:
                    yield response
        finally:
            connection.close()

    def call(self, service: str, type_name: str, request: dict[str, Any], timeout: float = CALL_TIMEOUT) -> Any:
        """Call a service with a request given as plain data; its response as plain data (the daemon
        fills and decodes them: no rclpy here)."""
        deadline = time.monotonic() + timeout
        params = {"service": service, "type": type_name, "request_data": request, "rate": None}
        for event in self.stream("call", params, lambda: time.monotonic() > deadline):
            if event["event"] == "response":
                return event["value"]
        raise RocError(f"'{service}' did not answer within {timeout:g} s")


def measure_rates(feed: Feed, topics: list[str], take: Callable[[dict[str, Any]], None],
                  stop: Callable[[], bool]) -> None:
    """Feed ``take`` the ``stats`` batches of ``topics`` until ``stop()``. A topic whose type the
    daemon cannot load ends the request before its ``subscribed`` event (topics are subscribed in
    order): it is left out, and the others are asked for again."""
    topics = list(topics)
    while topics and not stop():
        subscribed = 0
        try:
            for event in feed.stream("stats", {"topics": topics}, stop):
                if event["event"] == "subscribed":
                    subscribed += 1
                elif event["event"] == "batch":
                    take(event)
            return
        except DaemonError:
            if subscribed >= len(topics):
                raise
            del topics[subscribed]
