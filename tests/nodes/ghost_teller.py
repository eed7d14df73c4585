"""A process that tells, on ros_discovery_info, a node whose endpoint nothing announces: node /ghost, with
one writer GID no participant has, told as its own participant's (a message names the participant it
tells of, and rmw_dds_common's readers take the latest for each). Its message comes from a writer of its
own, made through rmw as roc's reader is (rcl cannot name the topic), told every 0.1 s: a reader takes
the latest of the two writers' messages, this one's or rmw's. Prints "ready" once the message is
published, then tells it again until killed."""

from __future__ import annotations

import ctypes
import os
import time

import rclpy
from rclpy.node import Node
from rclpy.serialization import serialize_message
from rclpy.signals import SignalHandlerOptions
from rmw_dds_common.msg import Gid, NodeEntitiesInfo, ParticipantEntitiesInfo

from roc.ros.discovery import DISCOVERY_TOPIC
from roc.ros.discovery_info import discovery_qos
from roc.ros.native import Gid as RmwGid
from roc.ros.native import QosProfile, SerializedMessage, rmw_library, rmw_node, type_support

PARTICIPANT_ENTITY = bytes.fromhex("000001c1")  # a participant's entity id (RTPS 9.3.1.2)
GHOST_ENTITY = bytes.fromhex("00abcd03")  # a writer's entity id no participant of the tests uses


class PublisherOptions(ctypes.Structure):  # rmw_publisher_options_t
    _fields_ = [("rmw_specific_publisher_payload", ctypes.c_void_p),
                ("require_unique_network_flow_endpoints", ctypes.c_int)]


def main() -> None:
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)  # SIGTERM ends the process
    node = Node(f"ghost_teller_{os.getpid()}")
    rmw = rmw_library()
    rmw.rmw_create_publisher.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_char_p,
                                         ctypes.POINTER(QosProfile), ctypes.POINTER(PublisherOptions)]
    rmw.rmw_create_publisher.restype = ctypes.c_void_p
    rmw.rmw_get_gid_for_publisher.argtypes = [ctypes.c_void_p, ctypes.POINTER(RmwGid)]
    rmw.rmw_publish_serialized_message.argtypes = [ctypes.c_void_p, ctypes.POINTER(SerializedMessage),
                                                   ctypes.c_void_p]
    publisher = rmw.rmw_create_publisher(rmw_node(node), type_support(ParticipantEntitiesInfo),
                                         DISCOVERY_TOPIC.encode(), ctypes.byref(discovery_qos(1)),
                                         ctypes.byref(PublisherOptions()))
    assert publisher, "rmw_create_publisher failed"
    own = RmwGid()
    assert rmw.rmw_get_gid_for_publisher(publisher, ctypes.byref(own)) == 0
    prefix = bytes(own.data)[:12]  # the participant's GUID prefix, which its endpoints share
    ghost = NodeEntitiesInfo(node_namespace="/", node_name="ghost",
                             writer_gid_seq=[Gid(data=list(prefix + GHOST_ENTITY + bytes(len(own.data) - 16)))])
    message = ParticipantEntitiesInfo(gid=Gid(data=list(prefix + PARTICIPANT_ENTITY + bytes(len(own.data) - 16))),
                                      node_entities_info_seq=[ghost])
    data = serialize_message(message)
    buffer = (ctypes.c_uint8 * len(data)).from_buffer_copy(data)
    serialized = SerializedMessage(buffer=buffer, buffer_length=len(data), buffer_capacity=len(data))
    assert rmw.rmw_publish_serialized_message(publisher, ctypes.byref(serialized), None) == 0
    print("ready", flush=True)
    while True:  # told again and again: the latest message of the participant, after the one rmw's writer tells
        time.sleep(0.1)
        assert rmw.rmw_publish_serialized_message(publisher, ctypes.byref(serialized), None) == 0


if __name__ == "__main__":
    main()
