"""Decoded messages for a client that loads no rclpy (``roc tui``): the ``values`` stream subscribes to a
topic and sends every message as plain data (its logs, its diagnostics), or only some numeric fields of
each (its plots: at 1 kHz a batch of numbers, not of messages), with the times they were published;
the ``decode`` stream turns CDR a client read from a bag into plain data.

The subscription is roc.ros.raw_subscription's Receiver, as for ``echo``: taken as messages arrive,
losses counted from the publishers' sequence numbers.
"""

from __future__ import annotations

import base64
import re
import time
from typing import Any

from rclpy.serialization import deserialize_message

from roc.errors import RocError
from roc.ros.dataplane import MAX_BATCH, _topic_class, subscription_profile
from roc.ros.messages import MessageValueError, field_names, value_to_data
from roc.ros.protocol import HEARTBEAT_SECONDS, Events
from roc.ros.raw_subscription import Receiver
from roc.ros.types import message_class

_INDEXED = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\[(-?\d+)\]$")


def field_path(path: str) -> list[str | int]:
    """``pose.pose.position.x`` or ``ranges[3]`` (also ``ranges.3``) as attribute names and indices."""
    steps: list[str | int] = []
    for name in field_names(path):
        indexed = _INDEXED.match(name)
        if indexed:
            steps += [indexed.group(1), int(indexed.group(2))]
        elif name.lstrip("-").isdigit():
            steps.append(int(name))
        else:
            steps.append(name)
    return steps


def number_at(message: Any, steps: list[str | int]) -> float | None:
    """The number at ``steps`` of ``message`` (a bool counts as 0 or 1), None where there is none (an
    index past the end, a field that is no number)."""
    value = message
    try:
        for step in steps:
            value = value[step] if isinstance(step, int) else getattr(value, step)
    except (AttributeError, IndexError, TypeError):
        return None
    if isinstance(value, (bool, int, float)) or hasattr(value, "item"):
        try:
            return float(value)
        except (TypeError, ValueError):
            return None
    return None


def check_fields(cls: Any, paths: list[str]) -> list[list[str | int]]:
    """Each path's steps, after checking that it names a number of a default ``cls`` message (an index
    into a sequence cannot be checked on an empty one)."""
    sample, checked = cls(), []
    for path in paths:
        steps = field_path(path)
        value: Any = sample
        for step in steps:
            if isinstance(step, int):
                break
            if not hasattr(type(value), "SLOT_TYPES") or step not in value.get_fields_and_field_types():
                known = ", ".join(value.get_fields_and_field_types()) if hasattr(value, "SLOT_TYPES") else ""
                raise MessageValueError(f"{path}: no field '{step}'" + (f" ({known})" if known else ""))
            value = getattr(value, step)
        else:
            if number_at(sample, steps) is None:
                raise MessageValueError(f"{path}: not a number ({type(value).__name__})")
        checked.append(steps)
    return checked


def values(graph, params: dict[str, Any]) -> Events:
    """Subscribe to ``params["topic"]`` (QoS following its publishers, as echo does: a transient local
    /rosout gives its recent history too) and yield ``subscribed {type}`` (after waiting, with
    heartbeats, for the topic to appear), then per batch of messages either ``values {messages: [{value,
    time, publisher}]}`` (each message as plain data; ``truncate_length`` cuts strings and arrays) or,
    with ``fields`` (dotted paths to numbers), ``samples {time: [...], values: {path: [...]}, lost}``
    (``time``: the publication's source timestamp in ns; a field a message lacks is null). With ``period``
    (seconds), a batch waits that long for more messages: a plot of a 1 kHz topic gets 20 events a
    second instead of hundreds."""
    topic = params["topic"]
    cls, type_name, found = yield from _topic_class(graph, topic, {"wait": params.get("wait", 0.0)},
                                                    wait_for_type=True)
    paths = params.get("fields") or []
    steps = check_fields(cls, paths) if paths else []
    receiver = Receiver(graph.node)
    try:
        receiver.subscribe(topic, cls, topic, subscription_profile(params.get("qos", {}), found))
        yield {"event": "subscribed", "type": type_name}
        last_sequence: dict[str, int] = {}
        while True:
            batch = receiver.batch(HEARTBEAT_SECONDS, MAX_BATCH)
            if not batch:
                yield {"event": "heartbeat"}
                continue
            due = time.monotonic() + params.get("period", 0.0)
            while len(batch) < MAX_BATCH and (remaining := due - time.monotonic()) > 0:
                batch += receiver.batch(remaining, MAX_BATCH - len(batch))
            lost: int | None = 0  # None: unknown, where the middleware gives no sequence numbers (Cyclone DDS)
            times, decoded = [], []
            for _, data, info in batch:
                sequence, gid = info.get("publication_sequence_number"), info.get("gid", "")
                previous = last_sequence.get(gid)
                if sequence is None:
                    lost = None
                else:
                    if lost is not None and previous is not None:
                        lost += max(0, sequence - previous - 1)
                    last_sequence[gid] = sequence
                times.append(info.get("source_timestamp") or info.get("received_timestamp") or time.time_ns())
                decoded.append(deserialize_message(data, cls))
            if paths:
                yield {"event": "samples", "time": times, "lost": lost,
                       "values": {path: [number_at(m, s) for m in decoded] for path, s in zip(paths, steps)}}
            else:
                limit = params.get("truncate_length")
                yield {"event": "values", "lost": lost, "messages": [
                    {"value": value_to_data(m, truncate_length=limit), "time": t, "publisher": info.get("gid")}
                    for m, t, (_, _, info) in zip(decoded, times, batch)]}
    finally:
        receiver.close()


def decode(graph, params: dict[str, Any]) -> Events:
    """``params["messages"]`` (base64 CDR of ``type`` messages) as plain data: one ``values {messages:
    [{value}]}`` event (``truncate_length`` as for ``values``)."""
    cls = message_class(params["type"])
    try:
        decoded = [deserialize_message(base64.b64decode(data), cls) for data in params["messages"]]
    except Exception as error:  # noqa: BLE001 - bytes that are no such message
        raise RocError(f"cannot decode a {params['type']} message: {error}") from None
    limit = params.get("truncate_length")
    yield {"event": "values", "messages": [{"value": value_to_data(m, truncate_length=limit)} for m in decoded]}
