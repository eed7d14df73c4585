"""Service calls and action goals as streams of plain-data events (see roc.ros.dataplane): the request
or goal travels as CDR, or as plain data for a client that loads no rclpy (``roc tui``), which then gets
the answers as plain data too (``value``); the client is created on the Graph's node and destroyed when
the stream closes; a goal still running then is canceled."""

from __future__ import annotations

import base64
import time
import uuid
from collections.abc import Callable, Generator, Iterator
from functools import partial
from typing import Any

from rclpy.qos import QoSProfile
from rclpy.serialization import deserialize_message

from roc.ros.cdr import serialize
from roc.ros.messages import fill_message, value_to_data
from roc.ros.protocol import HEARTBEAT_SECONDS, Events
from roc.ros.raw_subscription import RawSubscription
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
    graph.refuse_crashing_request(params["service"])
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


FEEDBACK_DEPTH = 100  # feedback messages kept between two takes, POLL_SECONDS apart
POLL_SECONDS = 0.005
CLEANUP_SECONDS = 2.0  # a canceled goal's response, and the client's end, waited for at most
GOAL_STATUS = {0: "UNKNOWN", 1: "ACCEPTED", 2: "EXECUTING", 3: "CANCELING", 4: "SUCCEEDED", 5: "CANCELED",
               6: "ABORTED"}


def goal(graph, params: dict[str, Any]) -> Events:
    """Send ``params["goal"]`` (base64 CDR of a ``type`` action's Goal; or ``goal_data``, plain data) to
    ``action``: ``waiting``
    while no server is available, then ``accepted {goal_id}`` (or ``rejected``), ``feedback {data}``
    (with ``feedback``), and ``result {data, status}``. Closed before the result, the goal is
    canceled."""
    from rclpy.action import ActionClient  # with numpy (unique_identifier_msgs): 0.1 s, for goals only
    from unique_identifier_msgs.msg import UUID

    cls = action_class(params["type"])
    request, plain = _received(params, "goal", cls.Goal), "goal_data" in params
    goal_id = UUID(uuid=list(uuid.uuid4().bytes))
    feedback = FeedbackReader(graph.node, cls, params["action"], bytes(goal_id.uuid)) \
        if params.get("feedback") else None
    # made and destroyed on the spinning thread: Kilted's rclpy (9.1) adds an action client to the
    # node's waitables before it is whole, and an executor that collects it then fails
    creating = graph.on_spinner(partial(ActionClient, graph.node, cls, params["action"]))
    handle = None
    try:
        yield from _wait(lambda: _done(creating))
        client = creating.result()
        if not client.wait_for_server(timeout_sec=0.1):
            yield {"event": "waiting"}
            yield from _wait(lambda: client.wait_for_server(timeout_sec=HEARTBEAT_SECONDS))
        sent = yield from _on_spinner(graph, partial(client.send_goal_async, request, goal_uuid=goal_id))
        yield from _wait(lambda: _done(sent))
        handle = sent.result()
        if not handle.accepted:
            handle = None
            yield {"event": "rejected"}
            return
        yield {"event": "accepted", "goal_id": bytes(handle.goal_id.uuid).hex()}
        result = yield from _on_spinner(graph, handle.get_result_async)
        beat = time.monotonic() + HEARTBEAT_SECONDS
        while True:
            finished = result.done()  # then every feedback the server sent before the result is taken below
            for message in feedback.take() if feedback else []:
                yield {"event": "feedback", **_answer(message, plain)}
            if finished:
                break
            if time.monotonic() >= beat:
                yield {"event": "heartbeat"}
                beat += HEARTBEAT_SECONDS
            time.sleep(POLL_SECONDS)
        outcome = result.result()
        handle = None
        status = GOAL_STATUS.get(outcome.status, "UNKNOWN")
        yield {"event": "result", **_answer(outcome.result, plain), "status": status}
    finally:
        if handle is not None:  # the client went away first: do not leave the goal running
            canceling = graph.on_spinner(handle.cancel_goal_async)
            if _done(canceling, CLEANUP_SECONDS):
                _done(canceling.result(), CLEANUP_SECONDS)
        # also when closed while the client was being made: it is made all the same
        if _done(creating, CLEANUP_SECONDS) and creating.exception() is None:
            _done(graph.on_spinner(creating.result().destroy), CLEANUP_SECONDS)
        if feedback is not None:
            feedback.destroy()


class FeedbackReader:
    """A goal's feedback, read from a subscription of roc's own rather than the action client's, for two
    reasons. The client's callback may run after its result future is done (rclpy handles a result
    that comes in the same wait before the feedback), so the last feedback was missed in 5 of 150
    goals on a busy machine; this subscription is outside any executor, so whatever came before the
    result is there to take once the result is done. And a server publishes its first feedback as soon
    as it has sent the goal's response, only to the readers it has discovered by then: rmw sends a
    response once the server has discovered the client's response reader, a participant's readers are
    discovered in the order they were made, and this one is made before the client's."""

    def __init__(self, node, cls: Any, action: str, goal_id: bytes) -> None:
        self._message_type = cls.Impl.FeedbackMessage
        self._goal_id = goal_id
        self._subscription = RawSubscription(node, self._message_type, f"{action}/_action/feedback",
                                             QoSProfile(depth=FEEDBACK_DEPTH))

    def take(self) -> list[Any]:
        """The goal's feedback messages that came since the last take, oldest first."""
        taken = self._subscription.take(FEEDBACK_DEPTH)
        messages = (deserialize_message(data, self._message_type) for data, _ in taken)
        return [message.feedback for message in messages if bytes(message.goal_id.uuid) == self._goal_id]

    def destroy(self) -> None:
        self._subscription.destroy()


def _on_spinner(graph, function: Callable[[], Any]) -> Generator[dict[str, Any], None, Any]:
    """Heartbeats while ``function()`` (an action client's request) runs on the Graph's spinning thread
    (Graph.on_spinner: why); returns what it returned."""
    running = graph.on_spinner(function)
    yield from _wait(lambda: _done(running))
    return running.result()


def _done(future, seconds: float = HEARTBEAT_SECONDS) -> bool:
    """Whether ``future`` (completed by the Graph's executor thread) is done, waiting up to
    ``seconds`` for it."""
    deadline = time.monotonic() + seconds
    while not future.done() and time.monotonic() < deadline:
        time.sleep(0.005)
    return future.done()
