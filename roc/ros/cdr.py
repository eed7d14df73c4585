"""Messages to and from their serialised CDR, as streams and requests carry them (base64 in JSON).
Kept apart from dataplane.py so that a verb converting a message loads rclpy's serialisation only."""

from __future__ import annotations

import base64
from typing import Any

from rclpy.serialization import deserialize_message, serialize_message

from roc.ros.types import message_class


def decode(message_type: str | type, data: str) -> Any:
    """A message object (a message type's name, or a class such as a service's Response) from base64
    CDR, as stream events carry messages."""
    cls = message_class(message_type) if isinstance(message_type, str) else message_type
    return deserialize_message(base64.b64decode(data), cls)


def serialize(message: Any) -> bytes:
    """A message's CDR, as a raw publisher sends it."""
    return serialize_message(message)


def encode(message: Any) -> str:
    """The base64 CDR of a message, for a ``publish`` request."""
    return base64.b64encode(serialize(message)).decode()
