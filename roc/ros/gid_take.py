"""A subscription whose messages come with the gid of the publisher that sent them.

rclpy 7 (Jazzy) leaves the publisher's gid out of the message info it gives Python, although rmw
fills it in; tf needs it to name the node behind each frame (tf messages do not say). So this
subscription is taken with rcl's ``rcl_take_serialized_message`` through ctypes, on the rcl handle
rclpy made for it. It is not in any executor: ``take`` is polled.
"""

from __future__ import annotations

import ctypes
import functools
from typing import Any

from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.qos import QoSProfile
from rclpy.type_support import check_is_valid_msg_type

from roc.errors import RocError

RCL_RET_OK = 0
RCL_RET_SUBSCRIPTION_TAKE_FAILED = 401  # nothing to take
GID_SIZE = 16  # RMW_GID_STORAGE_SIZE of Jazzy's rmw


class _Allocator(ctypes.Structure):  # rcutils_allocator_t
    _fields_ = [("allocate", ctypes.c_void_p), ("deallocate", ctypes.c_void_p), ("reallocate", ctypes.c_void_p),
                ("zero_allocate", ctypes.c_void_p), ("state", ctypes.c_void_p)]


class _Bytes(ctypes.Structure):  # rcutils_uint8_array_t (rmw_serialized_message_t)
    _fields_ = [("buffer", ctypes.POINTER(ctypes.c_uint8)), ("buffer_length", ctypes.c_size_t),
                ("buffer_capacity", ctypes.c_size_t), ("allocator", _Allocator)]


class _Gid(ctypes.Structure):  # rmw_gid_t
    _fields_ = [("implementation_identifier", ctypes.c_char_p), ("data", ctypes.c_uint8 * GID_SIZE)]


class _Info(ctypes.Structure):  # rmw_message_info_t
    _fields_ = [("source_timestamp", ctypes.c_int64), ("received_timestamp", ctypes.c_int64),
                ("publication_sequence_number", ctypes.c_uint64), ("reception_sequence_number", ctypes.c_uint64),
                ("publisher_gid", _Gid), ("from_intra_process", ctypes.c_bool)]


@functools.cache
def _libraries() -> tuple[ctypes.CDLL, ctypes.CDLL]:
    """librcl and librcutils as rclpy loaded them (dlopen finds a loaded library by its name)."""
    rcl, rcutils = ctypes.CDLL("librcl.so"), ctypes.CDLL("librcutils.so")
    rcutils.rcutils_get_default_allocator.restype = _Allocator
    rcutils.rcutils_uint8_array_init.argtypes = [ctypes.POINTER(_Bytes), ctypes.c_size_t, ctypes.POINTER(_Allocator)]
    rcutils.rcutils_uint8_array_fini.argtypes = [ctypes.POINTER(_Bytes)]
    rcl.rcl_take_serialized_message.argtypes = [ctypes.c_void_p, ctypes.POINTER(_Bytes), ctypes.POINTER(_Info),
                                                ctypes.c_void_p]
    rcl.rcl_take_serialized_message.restype = ctypes.c_int32
    return rcl, rcutils


def gid_text(gid) -> str:
    """A gid as roc writes it everywhere (graph endpoint infos too): hex bytes joined by dots."""
    return ".".join(format(x, "02x") for x in gid)


class GidSubscription:
    """A raw subscription on ``node``, read by ``take()``: [(CDR bytes, info)], info with ``gid``
    (the publisher's, as ``gid_text``), ``received_timestamp`` and ``publication_sequence_number``."""

    def __init__(self, node, msg_type: type, topic: str, qos: QoSProfile) -> None:
        check_is_valid_msg_type(msg_type)
        self._rcl, self._rcutils = _libraries()
        with node.handle:
            self._handle = _rclpy.Subscription(node.handle, msg_type, topic, qos.get_c_qos_profile())
        self._buffer = _Bytes()
        allocator = self._rcutils.rcutils_get_default_allocator()
        if self._rcutils.rcutils_uint8_array_init(ctypes.byref(self._buffer), 0, ctypes.byref(allocator)) != RCL_RET_OK:
            self._handle.destroy_when_not_in_use()
            raise RocError("cannot allocate a buffer for serialized messages")

    def take(self, most: int) -> list[tuple[bytes, dict[str, Any]]]:
        """Up to ``most`` messages waiting, oldest first."""
        taken = []
        while len(taken) < most:
            info = _Info()
            result = self._rcl.rcl_take_serialized_message(self._handle.pointer, ctypes.byref(self._buffer),
                                                           ctypes.byref(info), None)
            if result == RCL_RET_SUBSCRIPTION_TAKE_FAILED:
                break
            if result != RCL_RET_OK:
                raise RocError(f"rcl_take_serialized_message failed ({result})")
            taken.append((ctypes.string_at(self._buffer.buffer, self._buffer.buffer_length),
                          {"gid": gid_text(info.publisher_gid.data), "received_timestamp": info.received_timestamp,
                           "publication_sequence_number": info.publication_sequence_number}))
        return taken

    def destroy(self) -> None:
        self._handle.destroy_when_not_in_use()
        self._rcutils.rcutils_uint8_array_fini(ctypes.byref(self._buffer))
