"""roc.bag.qos profiles (plain dicts) to and from rclpy's QoSProfile."""

from __future__ import annotations

from typing import Any

from rclpy.duration import Duration
from rclpy.qos import DurabilityPolicy, HistoryPolicy, LivelinessPolicy, QoSProfile, ReliabilityPolicy

_POLICIES = {"history": HistoryPolicy, "reliability": ReliabilityPolicy, "durability": DurabilityPolicy,
             "liveliness": LivelinessPolicy}
_DURATIONS = ("deadline", "lifespan", "liveliness_lease_duration")


def _duration(duration: Duration) -> dict[str, int]:
    nanoseconds = duration.nanoseconds
    return {"sec": nanoseconds // 1_000_000_000, "nsec": nanoseconds % 1_000_000_000}


def offered(profile: QoSProfile) -> dict[str, Any]:
    """An endpoint's profile as a bag stores it (a remote publisher's history is ``unknown``)."""
    result: dict[str, Any] = {}
    for key in ("history", "depth", "reliability", "durability", "deadline", "lifespan", "liveliness",
                "liveliness_lease_duration", "avoid_ros_namespace_conventions"):
        value = getattr(profile, key)
        if key in _POLICIES:
            result[key] = value.name.lower()
        elif key in _DURATIONS:
            result[key] = _duration(value)
        else:
            result[key] = value
    return result


def profile(qos: dict[str, Any], depth: int | None = None) -> QoSProfile:
    """An rclpy profile; ``depth`` replaces a keep-last depth (a recorder's deeper history)."""
    history = qos["history"] if qos["history"] in ("keep_last", "keep_all") else "keep_last"
    kwargs: dict[str, Any] = {
        "history": HistoryPolicy.get_from_short_key(history),
        "depth": depth if depth is not None and history == "keep_last" else max(qos["depth"], 1),
    }
    for key in ("reliability", "durability", "liveliness"):
        value = qos[key] if qos[key] != "unknown" else "system_default"
        kwargs[key] = _POLICIES[key].get_from_short_key(value)
    for key in _DURATIONS:
        kwargs[key] = Duration(nanoseconds=qos[key]["sec"] * 1_000_000_000 + qos[key]["nsec"])
    kwargs["avoid_ros_namespace_conventions"] = qos["avoid_ros_namespace_conventions"]
    return QoSProfile(**kwargs)
