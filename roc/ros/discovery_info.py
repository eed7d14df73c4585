"""What every ROS participant says its nodes hold, read from ``ros_discovery_info``.

Each participant publishes there (rmw_dds_common's ParticipantEntitiesInfo: reliable, transient local,
again whenever they change) its nodes and the GIDs of their readers and writers. rmw's graph cache
takes the node names from it but shows an endpoint only once the endpoint's own announcement (SEDP)
has arrived, which may come later: under load one came 0.65 s after the rest of its participant's.
So a fresh participant holds the whole of another participant once it has that participant's latest
message and has discovered every node and endpoint the message lists
(roc.ros.discovery.incomplete_participants).

rcl cannot subscribe to that topic: it makes every name absolute, ``/ros_discovery_info``, which no
writer has. rmw takes a DDS name as given when ROS's conventions are avoided, so the reader is made
with ``rmw_create_subscription`` through ctypes, on the rmw node under an rclpy node. Its messages are
read from their CDR (``told_by``), without the message's Python class, whose Gid module imports numpy:
60 ms of every first query, which needs none of it.
"""

from __future__ import annotations

import ctypes
import functools

from roc.cdr_reader import Reader
from roc.errors import RocError
from roc.ros.discovery import DISCOVERY_TOPIC, Told, participant_prefix
from roc.ros.native import (
    GID_SIZE,
    RET_OK,
    MessageInfo,
    QosProfile,
    SerializedMessage,
    free_serialized_message,
    package_type_support,
    rmw_library,
    rmw_node,
    serialized_message,
)

# Every participant's message shares the topic's one instance, so the history must hold all that come
# between two takes (a take every poll of the discovery wait)
DEPTH = 1000
KEEP_LAST, RELIABLE, TRANSIENT_LOCAL = 1, 1, 1  # rmw_qos_*_policy_e values
MESSAGE_TYPE = ("rmw_dds_common", "msg__msg__participant_entities_info")  # its package, its C type support's name


class _Options(ctypes.Structure):  # rmw_subscription_options_t
    _fields_ = [("rmw_specific_subscription_payload", ctypes.c_void_p), ("ignore_local_publications", ctypes.c_bool),
                ("require_unique_network_flow_endpoints", ctypes.c_int), ("content_filter_options", ctypes.c_void_p)]


def discovery_qos(depth: int) -> QosProfile:
    """rmw_dds_common's profile of ``ros_discovery_info`` (reliable, transient local, its DDS name
    outside ROS's conventions), keeping ``depth`` messages."""
    return QosProfile(history=KEEP_LAST, depth=depth, reliability=RELIABLE, durability=TRANSIENT_LOCAL,
                      avoid_ros_namespace_conventions=True)


@functools.cache
def _rmw() -> ctypes.CDLL:
    rmw = rmw_library()
    rmw.rmw_create_subscription.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_char_p,
                                            ctypes.POINTER(QosProfile), ctypes.POINTER(_Options)]
    rmw.rmw_create_subscription.restype = ctypes.c_void_p
    rmw.rmw_take_serialized_message_with_info.argtypes = [
        ctypes.c_void_p, ctypes.POINTER(SerializedMessage), ctypes.POINTER(ctypes.c_bool),
        ctypes.POINTER(MessageInfo), ctypes.c_void_p]
    rmw.rmw_destroy_subscription.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    return rmw


def told_by(cdr: bytes) -> tuple[bytes, Told]:
    """The GUID prefix of the participant a message names, and what it tells, from the message's CDR
    (rmw_dds_common's ParticipantEntitiesInfo: its Gid, then a sequence of NodeEntitiesInfo, each a
    namespace, a name and two sequences of Gid, its readers' and its writers'; a Gid is char[16]).
    RocError for a message that ends early."""
    reader = Reader(cdr, f"{DISCOVERY_TOPIC} message")
    participant = reader.octets(GID_SIZE)
    nodes, endpoints = set(), set()
    for _ in range(int(reader.number("I"))):
        namespace, name = reader.text(), reader.text()
        nodes.add((namespace, name))
        for _ in ("readers", "writers"):
            endpoints.update([reader.octets(GID_SIZE) for _ in range(int(reader.number("I")))])
    return participant_prefix(participant), Told(nodes=frozenset(nodes), endpoints=frozenset(endpoints))


class DiscoveryInfoReader:
    """A reader of ``ros_discovery_info`` on ``node``'s participant (its own participant's messages too);
    ``take`` gives each participant's latest, ``close`` destroys it (before the node). A message is taken
    as the participant it names (its ``gid``): the message info's publisher GID is no GUID on every
    middleware (Cyclone DDS puts an instance handle there)."""

    def __init__(self, node) -> None:
        self._rmw = _rmw()
        self._node = node
        self._rmw_node = rmw_node(node)
        qos = discovery_qos(DEPTH)
        options = _Options(ignore_local_publications=False)
        self._subscription = self._rmw.rmw_create_subscription(
            self._rmw_node, package_type_support(*MESSAGE_TYPE), DISCOVERY_TOPIC.encode(), ctypes.byref(qos),
            ctypes.byref(options))
        if not self._subscription:
            raise RocError(f"the middleware cannot subscribe to {DISCOVERY_TOPIC}")
        self._buffer = serialized_message()
        self._latest: dict[bytes, Told] = {}

    def take(self) -> dict[bytes, Told]:
        """What each participant (by GUID prefix) told last, with every message that came since the last take."""
        taken, info = ctypes.c_bool(), MessageInfo()
        while True:
            result = self._rmw.rmw_take_serialized_message_with_info(
                self._subscription, ctypes.byref(self._buffer), ctypes.byref(taken), ctypes.byref(info), None)
            if result != RET_OK:
                raise RocError(f"taking from {DISCOVERY_TOPIC} failed ({result})")
            if not taken.value:
                return dict(self._latest)
            try:
                prefix, told = told_by(self._buffer.data())
            except RocError:  # not rmw_dds_common's layout: nothing to learn from it
                continue
            self._latest[prefix] = told

    def close(self) -> None:
        with self._node.handle:
            self._rmw.rmw_destroy_subscription(self._rmw_node, self._subscription)
        free_serialized_message(self._buffer)
