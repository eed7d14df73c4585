"""What the storages read and write: one message of a bag, and a file's summary."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

from roc.bag.metadata import Topic


class Message(NamedTuple):
    """A serialised message: ``log_time`` is when it was received (rosbag2's recv_timestamp, what
    playback follows), ``publish_time`` when it was sent (0 when the storage does not keep it)."""

    topic: str
    data: bytes
    log_time: int
    publish_time: int


@dataclass
class Definition:
    """A type's full definition as rosbag2 stores it: ``ros2msg`` or ``ros2idl`` text, or
    ``unknown`` with no text when none was found."""

    type: str
    encoding: str
    text: str
    type_hash: str = ""


@dataclass
class FileSummary:
    """What a storage file holds, found without reading every message when the file has an index."""

    topics: list[Topic]
    counts: dict[str, int]  # messages per topic
    start: int  # first message's log time (0 for none)
    end: int  # last message's log time
    message_count: int
    definitions: dict[str, Definition] = field(default_factory=dict)  # by type
    bag_metadata: str = ""  # rosbag2's serialised metadata kept in the file, if any
    complete: bool = True  # False: the file was not closed (recording killed); counted by reading it
