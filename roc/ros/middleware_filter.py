"""Content filters evaluated by the middleware: a DDS content-filtered topic behind an rcl
subscription (``rcl_subscription_set_content_filter``, through ctypes, since Jazzy's rclpy has no
content filter options). Fast DDS then sends a matched filtered reader only the samples that pass:
the filter runs on the writer's side, so filtered-out messages never cross the wire.

Setting a filter on an existing Fast DDS subscription deletes its DataReader before it creates the
filtered topic, and a filter Fast DDS refuses leaves the subscription without a reader (the next take
would crash the process). So the filter is first tried on a throwaway subscription created with it
(``rcl_subscription_init`` with content filter options: a refused filter is a clean error there),
and only a filter the middleware took there is set on the real one."""

from __future__ import annotations

import ctypes
import functools
from typing import Any

from roc.errors import RocError
from roc.ros.native import RET_OK, Allocator, type_support

RCL_RET_UNSUPPORTED = 3
_SPARE = 256  # bytes after each struct roc declares: room for fields a newer rcl adds at the end


class _FilterOptions(ctypes.Structure):  # rcl_subscription_content_filter_options_t (zeroed: zero-initialized)
    _fields_ = [("filter_expression", ctypes.c_char_p), ("size", ctypes.c_size_t),
                ("data", ctypes.POINTER(ctypes.c_char_p)), ("allocator", Allocator),
                ("_spare", ctypes.c_uint8 * _SPARE)]


class _SubscriptionOptions(ctypes.Structure):  # rcl_subscription_options_t, only handed to rcl
    _fields_ = [("_bytes", ctypes.c_uint8 * (1024 + _SPARE))]


class _ErrorString(ctypes.Structure):  # rcutils_error_string_t
    _fields_ = [("text", ctypes.c_char * 1024)]


@functools.cache
def _libraries() -> tuple[ctypes.CDLL, ctypes.CDLL]:
    rcl, rcutils = ctypes.PyDLL("librcl.so"), ctypes.PyDLL("librcutils.so")
    rcl.rcl_subscription_get_default_options.restype = _SubscriptionOptions
    rcl.rcl_subscription_options_set_content_filter_options.argtypes = [
        ctypes.c_char_p, ctypes.c_size_t, ctypes.POINTER(ctypes.c_char_p), ctypes.POINTER(_SubscriptionOptions)]
    rcl.rcl_subscription_options_fini.argtypes = [ctypes.POINTER(_SubscriptionOptions)]
    rcl.rcl_subscription_init.argtypes = [ctypes.POINTER(ctypes.c_void_p), ctypes.c_void_p, ctypes.c_void_p,
                                          ctypes.c_char_p, ctypes.POINTER(_SubscriptionOptions)]
    rcl.rcl_subscription_fini.argtypes = [ctypes.POINTER(ctypes.c_void_p), ctypes.c_void_p]
    rcl.rcl_subscription_content_filter_options_init.argtypes = [
        ctypes.c_void_p, ctypes.c_char_p, ctypes.c_size_t, ctypes.POINTER(ctypes.c_char_p),
        ctypes.POINTER(_FilterOptions)]
    rcl.rcl_subscription_content_filter_options_fini.argtypes = [ctypes.c_void_p, ctypes.POINTER(_FilterOptions)]
    rcl.rcl_subscription_set_content_filter.argtypes = [ctypes.c_void_p, ctypes.POINTER(_FilterOptions)]
    rcl.rcl_subscription_is_cft_enabled.argtypes = [ctypes.c_void_p]
    rcl.rcl_subscription_is_cft_enabled.restype = ctypes.c_bool
    rcutils.rcutils_get_error_string.restype = _ErrorString
    return rcl, rcutils


def _error(rcutils: ctypes.CDLL) -> str:
    """rcl's error message, then cleared (its place in the code, after ', at ', left out)."""
    text = rcutils.rcutils_get_error_string().text.decode(errors="replace")
    rcutils.rcutils_reset_error()
    return text.split(", at ")[0].strip() or "no reason given"


def _arguments(parameters: list[str]) -> Any:
    return (ctypes.c_char_p * max(len(parameters), 1))(*[p.encode() for p in parameters])


def _refusal(node, msg_type: type, topic: str, expression: str, parameters: list[str]) -> str | None:
    """Why the middleware refuses the filter on a subscription created with it; None when it takes it."""
    rcl, rcutils = _libraries()
    options = rcl.rcl_subscription_get_default_options()
    if rcl.rcl_subscription_options_set_content_filter_options(
            expression.encode(), len(parameters), _arguments(parameters), ctypes.byref(options)) != RET_OK:
        return _error(rcutils)
    probe = ctypes.c_void_p()  # rcl_subscription_t: one pointer, zero-initialized
    with node.handle:
        result = rcl.rcl_subscription_init(ctypes.byref(probe), node.handle.pointer, type_support(msg_type),
                                           topic.encode(), ctypes.byref(options))
        if result != RET_OK:
            refused = _error(rcutils)
            rcl.rcl_subscription_options_fini(ctypes.byref(options))
            rcutils.rcutils_reset_error()
            return refused
        # the subscription owns the options' filter now: its fini frees them
        enabled = rcl.rcl_subscription_is_cft_enabled(ctypes.addressof(probe))
        rcl.rcl_subscription_fini(ctypes.byref(probe), node.handle.pointer)
    return None if enabled else "the middleware does not filter content"


def set_filter(node, subscription, msg_type: type, topic: str, expression: str, parameters: list[str]) -> str | None:
    """Have the middleware filter ``subscription``'s (an rclpy subscription handle's) messages with
    ``expression`` (parameters as DDS literals). None when it does; else why not, in a few words (the
    subscription then receives every message, and roc filters them)."""
    import os

    rcl, rcutils = _libraries()
    middleware = os.environ.get("RMW_IMPLEMENTATION") or "the middleware"
    refused = _refusal(node, msg_type, topic, expression, parameters)
    if refused is not None:
        return f"{middleware} does not filter it ({refused})"
    options = _FilterOptions()
    with subscription:
        pointer = subscription.pointer
        if rcl.rcl_subscription_content_filter_options_init(pointer, expression.encode(), len(parameters),
                                                            _arguments(parameters), ctypes.byref(options)):
            return f"{middleware} does not filter it ({_error(rcutils)})"
        try:
            result = rcl.rcl_subscription_set_content_filter(pointer, ctypes.byref(options))
        finally:
            rcl.rcl_subscription_content_filter_options_fini(pointer, ctypes.byref(options))
        if result == RCL_RET_UNSUPPORTED:
            _error(rcutils)
            return f"{middleware} does not support content filters"
        if result != RET_OK:  # the throwaway subscription took the same filter: not expected
            raise RocError(f"the middleware failed to set the content filter on {topic}: {_error(rcutils)}")
        if not rcl.rcl_subscription_is_cft_enabled(pointer):
            return f"{middleware} does not filter content"
    return None
