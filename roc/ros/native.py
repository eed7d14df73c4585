"""ROS's C structures that roc hands to rcl, rmw and rcutils through ctypes where rclpy has no binding
(raw takes with the whole message info, middleware content filters, the ``ros_discovery_info`` reader),
and the serialized-message buffers they fill. The libraries are the ones rclpy loaded: dlopen finds a
loaded library by its name. They are PyDLLs, whose calls keep Python's lock: a take is a copy, and
releasing the lock around each one lets any busy thread of the process hold it for a switch interval
(5 ms) per message taken."""

from __future__ import annotations

import ctypes
import functools
from typing import Any

from roc.errors import RocError
from roc.ros.protocol import middleware

RET_OK = 0  # RCL_RET_OK, RMW_RET_OK
GID_SIZE = 16  # RMW_GID_STORAGE_SIZE (Jazzy, Kilted)


class Allocator(ctypes.Structure):  # rcutils_allocator_t
    _fields_ = [("allocate", ctypes.c_void_p), ("deallocate", ctypes.c_void_p), ("reallocate", ctypes.c_void_p),
                ("zero_allocate", ctypes.c_void_p), ("state", ctypes.c_void_p)]


class SerializedMessage(ctypes.Structure):  # rcutils_uint8_array_t (rmw_serialized_message_t)
    _fields_ = [("buffer", ctypes.POINTER(ctypes.c_uint8)), ("buffer_length", ctypes.c_size_t),
                ("buffer_capacity", ctypes.c_size_t), ("allocator", Allocator)]

    def data(self) -> bytes:
        """The message taken last, as CDR bytes."""
        return ctypes.string_at(self.buffer, self.buffer_length)


class Gid(ctypes.Structure):  # rmw_gid_t
    _fields_ = [("implementation_identifier", ctypes.c_char_p), ("data", ctypes.c_uint8 * GID_SIZE)]


class MessageInfo(ctypes.Structure):  # rmw_message_info_t
    _fields_ = [("source_timestamp", ctypes.c_int64), ("received_timestamp", ctypes.c_int64),
                ("publication_sequence_number", ctypes.c_uint64), ("reception_sequence_number", ctypes.c_uint64),
                ("publisher_gid", Gid), ("from_intra_process", ctypes.c_bool)]


class Duration(ctypes.Structure):  # rmw_time_t; zero: the middleware's default
    _fields_ = [("sec", ctypes.c_uint64), ("nsec", ctypes.c_uint64)]


class QosProfile(ctypes.Structure):  # rmw_qos_profile_t
    _fields_ = [("history", ctypes.c_int), ("depth", ctypes.c_size_t), ("reliability", ctypes.c_int),
                ("durability", ctypes.c_int), ("deadline", Duration), ("lifespan", Duration),
                ("liveliness", ctypes.c_int), ("liveliness_lease_duration", Duration),
                ("avoid_ros_namespace_conventions", ctypes.c_bool)]


@functools.cache
def rcutils() -> ctypes.CDLL:
    library = ctypes.PyDLL("librcutils.so")
    library.rcutils_get_default_allocator.restype = Allocator
    library.rcutils_uint8_array_init.argtypes = [ctypes.POINTER(SerializedMessage), ctypes.c_size_t,
                                                 ctypes.POINTER(Allocator)]
    library.rcutils_uint8_array_fini.argtypes = [ctypes.POINTER(SerializedMessage)]
    return library


@functools.cache
def rmw_library() -> ctypes.CDLL:
    """The rmw library rclpy's rcl loaded: rmw_implementation's, which passes each call on to the
    middleware chosen, where rcl links it; else the middleware's own (the wheels' rcl links Fast DDS's).
    Never another copy: a node of one rmw library is not one of another's."""
    loaded: dict[str, str] = {}
    with open("/proc/self/maps", encoding="utf-8") as maps:
        for line in maps:
            path = line.split()[-1]
            loaded.setdefault(path.rsplit("/", 1)[-1], path)
    for name in ("librmw_implementation.so", f"lib{middleware()}.so", "librmw_fastrtps_cpp.so"):
        if name in loaded:
            return ctypes.PyDLL(loaded[name])
    raise RocError("no rmw library is loaded in this process: is rclpy installed with its middleware?")


@functools.cache
def _node_get_rmw_handle() -> Any:
    function = ctypes.PyDLL("librcl.so").rcl_node_get_rmw_handle
    function.argtypes, function.restype = [ctypes.c_void_p], ctypes.c_void_p
    return function


def rmw_node(node) -> int:
    """The address of the rmw node under an rclpy node."""
    with node.handle:
        return _node_get_rmw_handle()(node.handle.pointer)


def serialized_message() -> SerializedMessage:
    """An empty buffer that takes grow as they need; ``free_serialized_message`` frees it."""
    buffer = SerializedMessage()
    library = rcutils()
    allocator = library.rcutils_get_default_allocator()
    if library.rcutils_uint8_array_init(ctypes.byref(buffer), 0, ctypes.byref(allocator)) != RET_OK:
        raise RocError("cannot allocate a buffer for serialized messages")
    return buffer


def free_serialized_message(buffer: SerializedMessage) -> None:
    rcutils().rcutils_uint8_array_fini(ctypes.byref(buffer))


def type_support(msg_type: type) -> int:
    """The address of ``msg_type``'s rosidl_message_type_support_t (imported if it is not yet)."""
    if getattr(msg_type, "_TYPE_SUPPORT", None) is None:
        msg_type.__class__.__import_type_support__()  # type: ignore[attr-defined]
    return _capsule_pointer(msg_type._TYPE_SUPPORT)  # type: ignore[attr-defined]


def package_type_support(package: str, name: str) -> int:
    """The address of the rosidl_message_type_support_t of ``package``'s message ``name`` as its C type
    support module names it (``msg__msg__participant_entities_info``): from that module alone, without
    the message's Python module, which may import numpy (60 ms) for a fixed-size array."""
    from rosidl_generator_py import import_type_support

    return _capsule_pointer(getattr(import_type_support(package), f"type_support_{name}"))


def _capsule_pointer(capsule: object) -> int:
    getter = ctypes.pythonapi.PyCapsule_GetPointer
    getter.restype, getter.argtypes = ctypes.c_void_p, [ctypes.py_object, ctypes.c_char_p]
    return getter(capsule, None)
