"""Service calls and action goals as streams of plain-data events (see roc.ros.dataplane): the request
or goal travels as CDR, or as plain data for a client that loads no rclpy (``roc tui``), which then gets
the answers as plain data too (``value``); the client is created on the Graph's node and destroyed when
the stream closes; a goal still running then is canceled."""

from __future__ import annotations

import base64
import queue
import threading
import time
from collections.abc import Callable, Iterator
from functools import partial
from typing import Any

from rclpy.serialization import deserialize_message

from roc.ros.cdr import serialize
from roc.ros.messages import fill_message, value_to_data
from roc.ros.protocol import HEARTBEAT_SECONDS, Events
from roc.ros.types import action_class, service_class


def _wait(done: Callable[[], bool]) -> Iterator[dict[str, Any]]:
    """Heartbeats until ``done()``."""
    while not done():
        yield {"event": "heartbeat"}


def _received(params: dict[str, Any], key: str, cls: Any) -> Any:
    """The request or goal ``params[key]`` (base64 CDR), or ``params[key + "_data"]`` (plain data)."""
    if f"{key}_data" in params:
        return fill_message(cls, params[f"{key}_data"])
    return deserialize_message(base64.b64decode(params[key]), cls)


def _answer(message: Any, plain: bool) -> dict[str, Any]:
    """A response, feedback or result: base64 CDR (``data``), and as plain data (``value``) for a
    client that sent plain data (``plain``)."""
    answer = {"data": base64.b64encode(serialize(message)).decode()}
    if plain:
        answer["value"] = value_to_data(message)
    return answer


def call(graph, params: dict[str, Any]) -> Events:
    """Call ``params["service"]`` (a ``type`` service) with ``request`` (base64 CDR; or ``request_data``,
    plain data): ``waiting`` while no server is available, then ``request`` and ``response {data,
    value?}`` per call; with ``rate`` (Hz) again and again until closed."""
    cls = service_class(params["type"])
    request, plain = _received(params, "request", cls.Request), "request_data" in params
    client = graph.node.create_client(cls, params["service"])
    try:
        if not client.wait_for_service(timeout_sec=0.1):
            yield {"event": "waiting"}
            yield from _wait(lambda: client.wait_for_service(timeout_sec=HEARTBEAT_SECONDS))
        period, due = 1.0 / params["rate"] if params.get("rate") else None, time.monotonic()
        while True:
            yield {"event": "request"}
            future = client.call_async(request)
            yield from _wait(partial(_done, future))
            yield {"event": "response", **_answer(future.result(), plain)}
            if period is None:
                return
            due += period
            while (remaining := due - time.monotonic()) > 0:
                time.sleep(min(remaining, HEARTBEAT_SECONDS))
                yield {"event": "heartbeat"}
    finally:
        graph.node.destroy_client(client)


GOAL_STATUS = {0: "UNKNOWN", 1: "ACCEPTED", 2: "EXECUTING", 3: "CANCELING", 4: "SUCCEEDED", 5: "CANCELED",
               6: "ABORTED"}


def goal(graph, params: dict[str, Any]) -> Events:
    """Send ``params["goal"]`` (base64 CDR of a ``type`` action's Goal; or ``goal_data``, plain data) to
    ``action``: ``waiting``
    while no server is available, then ``accepted {goal_id}`` (or ``rejected``), ``feedback {data}``
    (with ``feedback``), and ``result {data, status}``. Closed before the result, the goal is
    canceled."""
    from rclpy.action import ActionClient

    cls = action_class(params["type"])
    request, plain = _received(params, "goal", cls.Goal), "goal_data" in params
    client = ActionClient(graph.node, cls, params["action"])
    handle = None
    try:
        if not client.wait_for_server(timeout_sec=0.1):
            yield {"event": "waiting"}
            yield from _wait(lambda: client.wait_for_server(timeout_sec=HEARTBEAT_SECONDS))
        feedback: queue.SimpleQueue = queue.SimpleQueue()
        sent = client.send_goal_async(request, feedback_callback=feedback.put if params.get("feedback") else None)
        yield from _wait(lambda: _done(sent))
        handle = sent.result()
        if not handle.accepted:
            handle = None
            yield {"event": "rejected"}
            return
        yield {"event": "accepted", "goal_id": bytes(handle.goal_id.uuid).hex()}
        result = handle.get_result_async()
        while True:
            finished = _done(result)
            while not feedback.empty():
                message = feedback.get().feedback
                yield {"event": "feedback", **_answer(message, plain)}
            if finished:
                break
            yield {"event": "heartbeat"}
        outcome = result.result()
        handle = None
        status = GOAL_STATUS.get(outcome.status, "UNKNOWN")
        yield {"event": "result", **_answer(outcome.result, plain), "status": status}
    finally:
        if handle is not None:  # the client went away first: do not leave the goal running
            canceled = threading.Event()
            handle.cancel_goal_async().add_done_callback(lambda _: canceled.set())
            canceled.wait(2.0)
        client.destroy()


def _done(future) -> bool:
    """Whether ``future`` (completed by the Graph's executor thread) is done, waiting up to a
    heartbeat for it."""
    deadline = time.monotonic() + HEARTBEAT_SECONDS
    while not future.done() and time.monotonic() < deadline:
        time.sleep(0.005)
    return future.done()
