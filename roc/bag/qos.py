"""QoS profiles as rosbag2 stores them (``offered_qos_profiles``) and as override files give them,
as plain dicts without rclpy.

A profile is a dict in the order rosbag2 writes it: ``history``, ``depth``, ``reliability``,
``durability``, ``deadline``, ``lifespan``, ``liveliness``, ``liveliness_lease_duration`` (each
duration ``{sec, nsec}``) and ``avoid_ros_namespace_conventions``. Policies are the names of metadata
version 9 (``keep_last``, ``reliable``, ...); versions before 9 stored rmw's enum numbers, which are
read too. Foxy's "infinite" durations are read as infinite, as rosbag2 does."""

from __future__ import annotations

from typing import Any

import yaml

from roc.errors import UsageError

# rmw's enum values, in order (metadata versions 4 to 8 store these numbers).
POLICIES = {
    "history": ("system_default", "keep_last", "keep_all", "unknown"),
    "reliability": ("system_default", "reliable", "best_effort", "unknown", "best_available"),
    "durability": ("system_default", "transient_local", "volatile", "unknown", "best_available"),
    "liveliness": ("system_default", "automatic", "manual_by_node", "manual_by_topic", "unknown",
                   "best_available"),
}
DURATIONS = ("deadline", "lifespan", "liveliness_lease_duration")
INFINITE = {"sec": 9223372036, "nsec": 854775807}  # RMW_DURATION_INFINITE
_FOXY_INFINITE = ({"sec": 9223372036, "nsec": 854775807}, {"sec": 0x7FFFFFFF, "nsec": 0xFFFFFFFF},
                  {"sec": 0x7FFFFFFF, "nsec": 0x7FFFFFFF})
DEFAULT_DEPTH = 10  # rmw_qos_profile_default


def default_profile() -> dict[str, Any]:
    """rmw_qos_profile_default: keep last 10, reliable, volatile, durations unspecified."""
    return {"history": "keep_last", "depth": DEFAULT_DEPTH, "reliability": "reliable", "durability": "volatile",
            "deadline": {"sec": 0, "nsec": 0}, "lifespan": {"sec": 0, "nsec": 0}, "liveliness": "system_default",
            "liveliness_lease_duration": {"sec": 0, "nsec": 0}, "avoid_ros_namespace_conventions": False}


def _policy(name: str, value: Any) -> str:
    values = POLICIES[name]
    if isinstance(value, bool) or not isinstance(value, (int, str)):
        raise ValueError(f"{name}: {value!r} is not a policy")
    if isinstance(value, int):
        if not 0 <= value < len(values):
            raise ValueError(f"{name}: {value} is not one of rmw's values")
        return values[value]
    text = value.strip().lower()
    if text not in values:
        raise ValueError(f"{name}: '{value}' is not one of {', '.join(values)}")
    return text


def _duration(name: str, value: Any) -> dict[str, int]:
    if value is None:
        return {"sec": 0, "nsec": 0}
    if not isinstance(value, dict) or "sec" not in value or "nsec" not in value:
        raise ValueError(f"{name}: durations need both sec and nsec")
    duration = {"sec": int(value["sec"]), "nsec": int(value["nsec"])}
    if duration["sec"] < 0 or duration["nsec"] < 0:
        raise ValueError(f"{name}: durations may not be negative")
    return dict(INFINITE) if duration in _FOXY_INFINITE else duration


def normalized(profile: dict[str, Any], partial: bool = False) -> dict[str, Any]:
    """A stored or given profile with names for policies and ``{sec, nsec}`` durations; ``partial``
    (an override file) starts from the default profile and allows missing keys."""
    result = default_profile() if partial else {}
    for key, value in profile.items():
        if key in POLICIES:
            result[key] = _policy(key, value)
        elif key in DURATIONS:
            result[key] = _duration(key, value)
        elif key == "depth":
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise ValueError(f"depth: {value!r} is not a non-negative integer")
            result[key] = value
        elif key == "avoid_ros_namespace_conventions":
            result[key] = bool(value)
        else:
            raise ValueError(f"unexpected key '{key}' for a QoS profile")
    missing = [key for key in default_profile() if key not in result]
    if missing:
        raise ValueError(f"missing {', '.join(missing)}")
    return {key: result[key] for key in default_profile()}


def parse_profiles(stored: Any) -> list[dict[str, Any]]:
    """``offered_qos_profiles`` as a bag stores it: a YAML string (metadata versions 4-8, MCAP channel
    metadata, sqlite3 topics) or a list (version 9); empty for none."""
    if isinstance(stored, str):
        stored = yaml.safe_load(stored) if stored.strip() else []
    if stored is None:
        return []
    if not isinstance(stored, list):
        raise ValueError("offered_qos_profiles is not a list")
    return [normalized(profile) for profile in stored]


def dump_profiles(profiles: list[dict[str, Any]]) -> str:
    """The YAML string rosbag2 (version 9) stores in MCAP channels and sqlite3 topics; '' for none."""
    return yaml.safe_dump(profiles, sort_keys=False, default_flow_style=False) if profiles else ""


def load_overrides(path) -> dict[str, dict[str, Any]]:
    """A ``--qos-profile-overrides-path`` file: {topic: profile}, each completed from the default
    profile as rclpy's QoSProfile does. One-line UsageError naming the file and topic."""
    from pathlib import Path

    from roc.fsutil import read_yaml

    document = read_yaml(Path(path))
    if not isinstance(document, dict):
        raise UsageError(f"{path}: expected a mapping of topic names to QoS profiles")
    overrides = {}
    for topic, profile in document.items():
        if not isinstance(profile, dict):
            raise UsageError(f"{path}: {topic}: expected a mapping of QoS policies")
        try:
            overrides[str(topic)] = normalized(profile, partial=True)
        except ValueError as error:
            raise UsageError(f"{path}: {topic}: {error}") from None
    return overrides


def request_for_offers(offers: list[dict[str, Any]]) -> dict[str, Any]:
    """What a recorder asks for to hear every publisher (rosbag2's adapt_request_to_offers):
    reliable only when every publisher is, transient local only when every publisher is."""
    profile = default_profile()
    if offers:
        profile["reliability"] = ("reliable" if all(o["reliability"] == "reliable" for o in offers)
                                  else "best_effort")
        profile["durability"] = ("transient_local" if all(o["durability"] == "transient_local" for o in offers)
                                 else "volatile")
    return profile


def _compatibility(profile: dict[str, Any]) -> tuple:
    return (profile["reliability"], profile["durability"], profile["deadline"]["sec"], profile["deadline"]["nsec"],
            profile["liveliness"], profile["liveliness_lease_duration"]["sec"],
            profile["liveliness_lease_duration"]["nsec"])


def offer_for_recorded(offers: list[dict[str, Any]]) -> tuple[dict[str, Any], bool]:
    """What a player offers for a topic recorded with ``offers`` (rosbag2's
    adapt_offer_to_recorded_offers): the recorded profile with the default history when every
    publisher offered the same compatibility policies, else the default profile. The flag says the
    offers were mixed (the caller warns)."""
    if not offers:
        return default_profile(), False
    if len({_compatibility(o) for o in offers}) == 1:
        return {**offers[0], "history": "keep_last", "depth": DEFAULT_DEPTH}, False
    return default_profile(), True
