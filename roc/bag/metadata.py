"""A bag's metadata as rosbag2 keeps it (``metadata.yaml``, versions 4 to 9), read and written.

roc writes version 9, as rosbag2 does in Jazzy and in Kilted: offered QoS profiles as a list, type
description hashes, per-file information, custom data and the ROS distribution (roc.distribution's)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from roc import distribution
from roc.bag.qos import parse_profiles
from roc.errors import RocError

METADATA_FILE = "metadata.yaml"
VERSION = 9
OLDEST_VERSION = 4
SERVICE_EVENT_SUFFIX = "/_service_event"


class BagError(RocError):
    """A bag that cannot be read or written: the message names the file and what is wrong."""


@dataclass
class Topic:
    """A topic of a bag (rosbag2's TopicMetadata); ``offered_qos_profiles`` as roc.bag.qos dicts."""

    name: str
    type: str
    serialization_format: str = "cdr"
    offered_qos_profiles: list[dict[str, Any]] = field(default_factory=list)
    type_description_hash: str = ""

    @property
    def transient_local(self) -> bool:
        """Offered transient local (``/tf_static``, ``/map``): a split recording may repeat its latest
        messages at the start of each file (roc.bag.writer)."""
        return any(profile.get("durability") == "transient_local" for profile in self.offered_qos_profiles)

    @property
    def is_service_event(self) -> bool:
        """A service's event topic (``/svc/_service_event`` of type ``pkg/srv/Name_Event``)."""
        return (self.name.endswith(SERVICE_EVENT_SUFFIX) and "/srv/" in self.type
                and self.type.endswith("_Event"))


@dataclass
class FileInfo:
    path: str
    starting_time: int  # ns since the epoch
    duration: int  # ns
    message_count: int


@dataclass
class BagMetadata:
    storage_identifier: str
    relative_file_paths: list[str] = field(default_factory=list)
    files: list[FileInfo] = field(default_factory=list)
    duration: int = 0
    starting_time: int = 0
    message_count: int = 0
    topics: list[tuple[Topic, int]] = field(default_factory=list)  # (topic, message count)
    compression_format: str = ""
    compression_mode: str = ""
    custom_data: dict[str, str] = field(default_factory=dict)
    ros_distro: str = ""
    version: int = VERSION
    bag_size: int = 0  # bytes on disk (not stored)

    @property
    def end_time(self) -> int:
        return self.starting_time + self.duration

    def topic(self, name: str) -> Topic | None:
        return next((topic for topic, _ in self.topics if topic.name == name), None)


def ros_distro() -> str:
    """The distribution written into new bags: the one roc works with (roc.distribution)."""
    return distribution.current().name


# ---- reading ------------------------------------------------------------------------------------

def _field(node: dict, key: str, where: str) -> Any:
    if not isinstance(node, dict) or key not in node:
        raise KeyError(f"{where}{key}")
    return node[key]


def _topic(node: dict, version: int, where: str) -> Topic:
    data = _field(node, "topic_metadata", where)
    where = f"{where}topic_metadata."
    profiles: Any = data.get("offered_qos_profiles", "") if version >= 4 else ""
    return Topic(name=str(_field(data, "name", where)), type=str(_field(data, "type", where)),
                 serialization_format=str(_field(data, "serialization_format", where)),
                 offered_qos_profiles=parse_profiles(profiles),
                 type_description_hash=str(data.get("type_description_hash") or "") if version >= 7 else "")


def from_document(document: Any, source: str) -> BagMetadata:
    """Metadata from a parsed ``metadata.yaml`` (or rosbag2's serialised metadata); BagError naming
    ``source`` and the missing or bad field."""
    try:
        info = _field(document, "rosbag2_bagfile_information", "") if "rosbag2_bagfile_information" in (
            document or {}) else document
        version = int(_field(info, "version", ""))
        if version < OLDEST_VERSION:
            raise BagError(f"{source}: metadata version {version} is older than the oldest roc reads "
                           f"({OLDEST_VERSION})")
        files = [FileInfo(path=str(f["path"]), starting_time=int(f["starting_time"]["nanoseconds_since_epoch"]),
                          duration=int(f["duration"]["nanoseconds"]), message_count=int(f["message_count"]))
                 for f in (info.get("files") or [])] if version >= 5 else []
        topics = [(_topic(t, version, f"topics_with_message_count[{i}]."), int(_field(t, "message_count", "")))
                  for i, t in enumerate(info.get("topics_with_message_count") or [])]
        return BagMetadata(
            version=version,
            storage_identifier=str(_field(info, "storage_identifier", "")),
            relative_file_paths=[str(p) for p in _field(info, "relative_file_paths", "") or []],
            files=files,
            duration=int(_field(info, "duration", "")["nanoseconds"]),
            starting_time=int(_field(info, "starting_time", "")["nanoseconds_since_epoch"]),
            message_count=int(_field(info, "message_count", "")),
            topics=topics,
            compression_format=str(info.get("compression_format") or ""),
            compression_mode=str(info.get("compression_mode") or ""),
            custom_data={str(k): str(v) for k, v in (info.get("custom_data") or {}).items()},
            ros_distro=str(info.get("ros_distro") or ""))
    except BagError:
        raise
    except KeyError as error:
        raise BagError(f"{source}: missing field '{error.args[0]}'") from None
    except (TypeError, ValueError, AttributeError) as error:
        raise BagError(f"{source}: malformed metadata ({error})") from None


def read_metadata(directory: Path) -> BagMetadata:
    path = directory / METADATA_FILE
    try:
        document = yaml.safe_load(path.read_text())
    except OSError as error:
        raise BagError(f"{path}: cannot read it ({error.strerror})") from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        raise BagError(f"{path}{f':{mark.line + 1}' if mark else ''}: not valid YAML") from None
    metadata = from_document(document, str(path))
    metadata.bag_size = directory_size(directory)
    return metadata


def directory_size(directory: Path) -> int:
    return sum(entry.stat().st_size for entry in directory.iterdir() if entry.is_file())


# ---- writing ------------------------------------------------------------------------------------

def to_document(metadata: BagMetadata) -> dict[str, Any]:
    """The ``rosbag2_bagfile_information`` mapping of version 9, in rosbag2's key order."""
    return {
        "version": VERSION,
        "storage_identifier": metadata.storage_identifier,
        "duration": {"nanoseconds": metadata.duration},
        "starting_time": {"nanoseconds_since_epoch": metadata.starting_time},
        "message_count": metadata.message_count,
        "topics_with_message_count": [
            {"topic_metadata": {"name": topic.name, "type": topic.type,
                                "serialization_format": topic.serialization_format,
                                "offered_qos_profiles": topic.offered_qos_profiles,
                                "type_description_hash": topic.type_description_hash},
             "message_count": count} for topic, count in metadata.topics],
        "compression_format": metadata.compression_format,
        "compression_mode": metadata.compression_mode,
        "relative_file_paths": list(metadata.relative_file_paths),
        "files": [{"path": f.path, "starting_time": {"nanoseconds_since_epoch": f.starting_time},
                   "duration": {"nanoseconds": f.duration}, "message_count": f.message_count}
                  for f in metadata.files],
        "custom_data": dict(metadata.custom_data),
        "ros_distro": metadata.ros_distro,
    }


def dump(metadata: BagMetadata) -> str:
    """rosbag2's serialised metadata (the text of metadata.yaml, also kept inside MCAP files)."""
    return yaml.safe_dump({"rosbag2_bagfile_information": to_document(metadata)}, sort_keys=False,
                          default_flow_style=False, allow_unicode=True)


def write_metadata(directory: Path, metadata: BagMetadata) -> None:
    from roc.fsutil import write_text_atomic

    write_text_atomic(directory / METADATA_FILE, dump(metadata))
