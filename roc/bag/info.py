"""``roc bag info``'s output: ros2 bag info's text (rosbag2's format_bag_metadata: files, size,
storage, distribution, duration, start and end in local time, messages, topics, services) and a
JSON document; with ``verbose``, each service's request and response counts, read from its events."""

from __future__ import annotations

import struct
import time
from typing import Any

from roc.bag.metadata import SERVICE_EVENT_SUFFIX, BagMetadata, Topic
from roc.bag.reader import Bag

INDENT = 19  # "Topic information: "
REQUEST_EVENTS = (0, 1)  # service_msgs/ServiceEventInfo: REQUEST_SENT, REQUEST_RECEIVED
RESPONSE_EVENTS = (2, 3)  # RESPONSE_SENT, RESPONSE_RECEIVED


def file_size(size: int) -> str:
    value, unit = float(size), 0
    units = ("B", "KiB", "MiB", "GiB", "TiB")
    while value >= 1024 and unit < 4:
        value /= 1024
        unit += 1
    return f"{value:.0f} {units[unit]}" if unit == 0 else f"{value:.1f} {units[unit]}"


def seconds(ns: int) -> str:
    """``1585866235.112411371``: whole seconds and nine digits, as rosbag2 prints times."""
    whole = ns // 1_000_000_000
    return f"{whole}.{ns - whole * 1_000_000_000:09d}"


def time_point(ns: int) -> str:
    """``Apr  2 2020 22:23:55.112411371 (1585866235.112411371)`` in local time."""
    whole = ns // 1_000_000_000
    try:
        local = time.localtime(whole)
        date = time.strftime("%b %e %Y %H:%M:%S", local)
    except (OverflowError, OSError, ValueError):
        date = "out of range"
    return f"{date}.{ns - whole * 1_000_000_000:09d} ({seconds(ns)})"


def service_name(topic: Topic) -> str:
    return topic.name[:-len(SERVICE_EVENT_SUFFIX)]


def service_type(topic: Topic) -> str:
    return topic.type[:-len("_Event")]


def _lines(first: str, items: list[str], indent: int) -> list[str]:
    if not items:
        return [first]
    return [first + items[0]] + [" " * indent + item for item in items[1:]]


def text(metadata: BagMetadata, service_counts: dict[str, tuple[int, int]] | None = None) -> str:
    """ros2 bag info's text; ``service_counts`` ({service: (requests, responses)}) is -v's."""
    topics = [(topic, count) for topic, count in metadata.topics if not topic.is_service_event]
    services = [(topic, count) for topic, count in metadata.topics if topic.is_service_event]
    service_messages = sum(count for _, count in services)
    lines = [""]
    lines += _lines("Files:             ", list(metadata.relative_file_paths), INDENT)
    lines += [f"Bag size:          {file_size(metadata.bag_size)}",
              f"Storage id:        {metadata.storage_identifier}",
              f"ROS Distro:        {metadata.ros_distro or 'unknown'}",
              f"Duration:          {seconds(metadata.duration)}s",
              f"Start:             {time_point(metadata.starting_time)}",
              f"End:               {time_point(metadata.end_time)}",
              f"Messages:          {metadata.message_count - service_messages}"]
    lines += _lines("Topic information: ", [
        f"Topic: {t.name} | Type: {t.type} | Count: {c} | Serialization Format: {t.serialization_format}"
        for t, c in topics], INDENT)
    lines.append(f"Service:           {len(services)}")
    if service_counts is None:
        lines += _lines("Service information: ", [
            f"Service: {service_name(t)} | Type: {service_type(t)} | Event Count: {c} | "
            f"Serialization Format: {t.serialization_format}" for t, c in services], INDENT + 2)
    else:
        lines += _lines("Service information: ", [
            f"Service: {service_name(t)} | Type: {service_type(t)} | "
            f"Request Count: {service_counts.get(service_name(t), (0, 0))[0]} | "
            f"Response Count: {service_counts.get(service_name(t), (0, 0))[1]} | "
            f"Serialization Format: {t.serialization_format}" for t, _ in services], len("Service information: "))
    return "\n".join(lines) + "\n"


def event_kind(data: bytes) -> tuple[int, bytes, int] | None:
    """(event type, client gid, sequence number) of a service event's CDR (its ServiceEventInfo:
    uint8 event_type, Time stamp, char[16] client_gid, int64 sequence_number), None if too short."""
    if len(data) < 44:
        return None
    order = "<" if data[1] & 1 else ">"
    return data[4], bytes(data[16:32]), struct.unpack(order + "q", data[36:44])[0]


def service_counts(bag: Bag) -> dict[str, tuple[int, int]]:
    """Requests and responses of each service: distinct (client, sequence number) pairs, as rosbag2."""
    events = [topic for topic in bag.topics() if topic.is_service_event]
    seen: dict[str, tuple[set, set]] = {service_name(topic): (set(), set()) for topic in events}
    if events:
        for message in bag.messages([topic.name for topic in events]):
            kind = event_kind(message.data)
            if kind is None:
                continue
            requests, responses = seen[message.topic[:-len(SERVICE_EVENT_SUFFIX)]]
            if kind[0] in REQUEST_EVENTS:
                requests.add(kind[1:])
            elif kind[0] in RESPONSE_EVENTS:
                responses.add(kind[1:])
    return {name: (len(requests), len(responses)) for name, (requests, responses) in seen.items()}


def document(metadata: BagMetadata, path: str, service_counts: dict[str, tuple[int, int]] | None = None,
             notes: list[str] | None = None) -> dict[str, Any]:
    """``--format json``: the same facts, numbers as numbers."""
    services = []
    for topic, count in metadata.topics:
        if topic.is_service_event:
            entry: dict[str, Any] = {"name": service_name(topic), "type": service_type(topic), "event_count": count,
                                     "serialization_format": topic.serialization_format}
            if service_counts is not None:
                entry["request_count"], entry["response_count"] = service_counts.get(service_name(topic), (0, 0))
            services.append(entry)
    return {
        "path": path,
        "files": list(metadata.relative_file_paths),
        "bag_size": metadata.bag_size,
        "storage": metadata.storage_identifier,
        "ros_distro": metadata.ros_distro,
        "metadata_version": metadata.version,
        "compression_mode": metadata.compression_mode,
        "compression_format": metadata.compression_format,
        "duration_s": metadata.duration / 1e9,
        "start_ns": metadata.starting_time,
        "end_ns": metadata.end_time,
        "message_count": metadata.message_count,
        "topics": [{"name": t.name, "type": t.type, "message_count": c, "serialization_format": t.serialization_format,
                    "type_description_hash": t.type_description_hash, "offered_qos_profiles": t.offered_qos_profiles}
                   for t, c in metadata.topics if not t.is_service_event],
        "services": services,
        "custom_data": metadata.custom_data,
        "notes": notes or [],
    }
