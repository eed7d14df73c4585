"""Raw subscriptions taken on a thread of their own, outside any executor, with the whole message info.

Two reasons. rclpy 7 (Jazzy) leaves the publisher's gid out of the message info it gives Python,
although rmw fills it in; tf needs it to name the node behind each frame, and echo to count losses per
publisher. And rclpy's Python executor costs so much per message that a 5 kHz topic overflows the
subscription's history on a busy machine, while its C++ EventsExecutor never calls a callback that
takes message info. So a RawSubscription is taken with rcl's ``rcl_take_serialized_message`` through
ctypes, on the rcl handle rclpy made for it, and a Receiver waits for messages in rcl (without
Python's lock) and takes each as it arrives, queueing it for whoever reads the batches.
"""

from __future__ import annotations

import collections
import ctypes
import functools
import threading
import time
from collections.abc import Hashable
from typing import Any

from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.qos import QoSProfile
from rclpy.type_support import check_is_valid_msg_type

from roc.errors import RocError
from roc.ros.native import RET_OK, MessageInfo, SerializedMessage, free_serialized_message, serialized_message

RCL_RET_SUBSCRIPTION_TAKE_FAILED = 401  # nothing to take
SEQUENCE_UNSUPPORTED = 2**64 - 1  # RMW_MESSAGE_INFO_SEQUENCE_NUMBER_UNSUPPORTED
MAX_TAKE = 1000  # messages taken from one subscription before the others get their turn
MAX_QUEUED_BYTES = 64 * 2**20  # taken messages a Receiver holds for a slow reader
# After taking, let messages gather this long before waiting again: at 5 kHz a wake per message
# costs more than the messages do.
GATHER_SECONDS = 0.002
WAIT_NANOSECONDS = 1_000_000_000  # a Receiver's longest wait in rcl (close wakes it at once)


@functools.cache
def _rcl() -> ctypes.CDLL:
    rcl = ctypes.PyDLL("librcl.so")
    rcl.rcl_take_serialized_message.argtypes = [ctypes.c_void_p, ctypes.POINTER(SerializedMessage),
                                                ctypes.POINTER(MessageInfo), ctypes.c_void_p]
    rcl.rcl_take_serialized_message.restype = ctypes.c_int32
    return rcl


def gid_text(gid) -> str:
    """A gid as roc writes it everywhere (graph endpoint infos too): hex bytes joined by dots."""
    return ".".join(format(x, "02x") for x in gid)


@functools.lru_cache(maxsize=1024)
def _known_gid_text(gid: bytes) -> str:
    """gid_text, computed once per publisher rather than per message."""
    return gid_text(gid)


def _info(info: MessageInfo) -> dict[str, Any]:
    """The message info as rclpy names it, plus ``gid`` (the publisher's, as ``gid_text``); an
    unsupported sequence number is None."""
    return {"source_timestamp": info.source_timestamp, "received_timestamp": info.received_timestamp,
            "publication_sequence_number": None if info.publication_sequence_number == SEQUENCE_UNSUPPORTED
            else info.publication_sequence_number,
            "reception_sequence_number": None if info.reception_sequence_number == SEQUENCE_UNSUPPORTED
            else info.reception_sequence_number,
            "gid": _known_gid_text(bytes(info.publisher_gid.data))}


class RawSubscription:
    """A raw subscription on ``node``, read by ``take()``: [(CDR bytes, info)] (info: see ``_info``).
    With ``content_filter`` (expression, parameters), the middleware filters its messages where it can;
    ``unfiltered`` then says why it does not (None when it does)."""

    def __init__(self, node, msg_type: type, topic: str, qos: QoSProfile,
                 content_filter: tuple[str, list[str]] | None = None) -> None:
        check_is_valid_msg_type(msg_type)
        self._rcl = _rcl()
        with node.handle:
            self._handle = _rclpy.Subscription(node.handle, msg_type, topic, qos.get_c_qos_profile())
        self.unfiltered: str | None = None
        if content_filter is not None:
            from roc.ros.middleware_filter import set_filter

            self.unfiltered = set_filter(node, self._handle, msg_type, topic, *content_filter)
        try:
            self._buffer = serialized_message()
        except RocError:
            self._handle.destroy_when_not_in_use()
            raise

    @property
    def handle(self):
        return self._handle

    def take(self, most: int) -> list[tuple[bytes, dict[str, Any]]]:
        """Up to ``most`` messages waiting, oldest first."""
        taken: list[tuple[bytes, dict[str, Any]]] = []
        while len(taken) < most:
            info = MessageInfo()
            result = self._rcl.rcl_take_serialized_message(self._handle.pointer, ctypes.byref(self._buffer),
                                                           ctypes.byref(info), None)
            if result == RCL_RET_SUBSCRIPTION_TAKE_FAILED:
                break
            if result != RET_OK:
                raise RocError(f"rcl_take_serialized_message failed ({result})")
            taken.append((self._buffer.data(), _info(info)))
        return taken

    def destroy(self) -> None:
        self._handle.destroy_when_not_in_use()
        free_serialized_message(self._buffer)


class Receiver:
    """Raw subscriptions on ``node`` (``subscribe``), whose messages a thread of its own takes as soon
    as they arrive, so that a slow reader of ``batch`` does not make a subscription's history
    overflow. Taken messages wait in memory up to MAX_QUEUED_BYTES; past that the thread stops
    taking, the histories drop the oldest and the publishers' sequence numbers show the loss.
    ``close`` stops the thread and destroys the subscriptions."""

    def __init__(self, node) -> None:
        self._node = node
        self._subscriptions: dict[Hashable, RawSubscription] = {}
        self._queued: collections.deque = collections.deque()
        self._queued_bytes = 0
        self._changed = threading.Condition()
        self._stopping = False
        self._failure: Exception | None = None
        self._wake = _rclpy.GuardCondition(node.context.handle)
        self._thread = threading.Thread(target=self._take_all, name="roc-receiver", daemon=True)
        self._thread.start()

    def subscribe(self, key: Hashable, msg_type: type, topic: str, qos: QoSProfile,
                  content_filter: tuple[str, list[str]] | None = None) -> str | None:
        """Receive ``topic``'s messages as ``key``'s; with ``content_filter``, returns why the
        middleware does not filter them (None when it does, see RawSubscription)."""
        subscription = RawSubscription(self._node, msg_type, topic, qos, content_filter)
        with self._changed:
            self._subscriptions[key] = subscription
        self._wake.trigger_guard_condition()
        return subscription.unfiltered

    def _take_all(self) -> None:
        wait_set: Any = None  # an rclpy WaitSet with room for ``size`` subscriptions
        size = -1
        try:
            while not self._stopping:
                with self._changed:
                    subscriptions = dict(self._subscriptions)
                if len(subscriptions) != size:  # a wait set has room for a fixed number of subscriptions
                    if wait_set is not None:
                        wait_set.destroy_when_not_in_use()
                    size = len(subscriptions)
                    wait_set = _rclpy.WaitSet(size, 1, 0, 0, 0, 0, self._node.context.handle)
                wait_set.clear_entities()
                for subscription in subscriptions.values():
                    wait_set.add_subscription(subscription.handle)
                wait_set.add_guard_condition(self._wake)
                wait_set.wait(WAIT_NANOSECONDS)  # Python's lock is free meanwhile
                taken = 0
                for key, subscription in subscriptions.items():
                    messages = subscription.take(MAX_TAKE)
                    self._queue(key, messages)
                    taken += len(messages)
                if taken:
                    time.sleep(GATHER_SECONDS)
        except Exception as error:  # noqa: BLE001 - handed to the reader, who reports it
            with self._changed:
                self._failure = error
                self._changed.notify_all()
        finally:
            if wait_set is not None:
                wait_set.destroy_when_not_in_use()

    def _queue(self, key: Hashable, taken: list[tuple[bytes, dict[str, Any]]]) -> None:
        with self._changed:
            while self._queued_bytes > MAX_QUEUED_BYTES and not self._stopping:
                self._changed.wait()
            self._queued.extend((key, data, info) for data, info in taken)
            self._queued_bytes += sum(len(data) for data, _ in taken)
            self._changed.notify_all()

    def batch(self, timeout: float, most: int = MAX_TAKE) -> list[tuple[Hashable, bytes, dict[str, Any]]]:
        """Up to ``most`` taken messages, oldest first, as (key, CDR bytes, info); waits up to
        ``timeout`` seconds for the first and is empty when none came."""
        with self._changed:
            self._changed.wait_for(lambda: self._queued or self._failure, timeout)
            if self._failure is not None:
                raise RocError(f"taking messages failed: {self._failure}")
            batch = [self._queued.popleft() for _ in range(min(most, len(self._queued)))]
            self._queued_bytes -= sum(len(data) for _, data, _ in batch)
            self._changed.notify_all()
        return batch

    def close(self) -> None:
        with self._changed:
            self._stopping = True
            self._changed.notify_all()
        self._wake.trigger_guard_condition()
        self._thread.join()
        for subscription in self._subscriptions.values():
            subscription.destroy()
        self._wake.destroy_when_not_in_use()
