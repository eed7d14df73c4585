"""Recording a live graph into a bag (``roc bag record``): topics and service event topics chosen by
a Selection, picked up as they appear (the graph is polled every ``polling_interval``), each
subscribed with QoS adapted to its publishers as rosbag2 does (or overridden), and its raw CDR
written as it arrives: messages are never deserialised. roc.ros.raw_subscription's Receiver takes
them on a thread of its own with the publisher's gid and sequence number, so every message lost
between a publisher and the recorder is counted.

It runs in the verb's process, not in the roc daemon: a recording moves megabytes per second that
the daemon would have to pass on as JSON lines, it must stop with its own Ctrl+C, and a crash or a
full disk must not take the daemon (and every other verb's graph) down with it."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from roc.bag.definitions import definition, type_hash_of
from roc.bag.metadata import Topic
from roc.bag.qos import default_profile, request_for_offers
from roc.bag.selection import Selection
from roc.bag.transport.ros_qos import offered, profile
from roc.bag.writer import BagWriter, DiskFull, WriteOptions
from roc.errors import RocError
from roc.ros.dataplane import RECEIVE_DEPTH
from roc.ros.graph import Graph
from roc.ros.raw_subscription import Receiver
from roc.ros.types import UnknownTypeError, message_class

CLOCK_TOPIC = "/clock"
CLOCK_KEY = ("clock",)  # the Receiver key of the /clock subscription of --use-sim-time
FLUSH_SECONDS = 0.5  # a sqlite3 bag commits at least this often
DRAIN_QUIET_SECONDS = 0.1
DRAIN_SECONDS = 2.0


@dataclass
class RecordOptions:
    uri: str
    write: WriteOptions
    selection: Selection
    overrides: dict[str, dict[str, Any]] = field(default_factory=dict)
    include_unpublished_topics: bool = False
    polling_interval: float = 0.1
    start_paused: bool = False
    use_sim_time: bool = False


@dataclass
class TopicStats:
    received: int = 0
    written: int = 0
    lost: int = 0  # gaps in the publishers' sequence numbers
    unsequenced: int = 0  # messages without a sequence number (Cyclone DDS gives none): their loss is unknown
    last_sequence: dict[str, int] = field(default_factory=dict)  # by publisher gid


@dataclass
class Result:
    metadata: Any
    stats: dict[str, TopicStats]
    paused_dropped: int
    before_clock_dropped: int
    error: str | None = None
    repeated: int = 0  # transient local messages written again at the start of split files


def _clock_ns(data: bytes) -> int | None:
    """The time of a rosgraph_msgs/Clock message, read from its CDR (int32 sec, uint32 nanosec)."""
    import struct

    if len(data) < 12:
        return None
    sec, nanosec = struct.unpack(("<" if data[1] & 1 else ">") + "iI", data[4:12])
    return sec * 1_000_000_000 + nanosec


class Recorder:
    """``report(line)`` receives what a user should see as it happens."""

    def __init__(self, options: RecordOptions, report: Callable[[str], None], warn: Callable[[str], None]) -> None:
        self.options = options
        self._report, self._warn = report, warn
        self.paused = options.start_paused
        self._stopping = False
        self._subscribed: dict[str, TopicStats] = {}
        self._ignored: set[str] = set()
        self._paused_dropped = self._before_clock_dropped = 0
        self._clock: int | None = None

    def stop(self) -> None:
        self._stopping = True

    def toggle_pause(self) -> None:
        self.paused = not self.paused
        self._report("Pausing recording." if self.paused else "Resuming recording.")

    def _discover(self, graph: Graph, receiver: Receiver, writer: BagWriter) -> None:
        node = graph.node
        for name, types in node.get_topic_names_and_types():
            if name in self._subscribed or name in self._ignored:
                continue
            if len(types) != 1:
                self._ignored.add(name)
                self._warn(f"topic {name} has several types ({', '.join(types)}): not recorded")
                continue
            type_name = types[0]
            if not self.options.selection.takes(name, type_name):
                continue
            publishers = node.get_publishers_info_by_topic(name)
            if not publishers and not self.options.include_unpublished_topics:
                continue  # looked at again at the next poll
            try:
                cls = message_class(type_name)
            except UnknownTypeError:
                self._ignored.add(name)
                self._warn(f"topic {name} has type {type_name}, which is not installed here: roc cannot subscribe "
                           "to it (install or source its package); not recorded")
                continue
            offers = [offered(p.qos_profile) for p in publishers]
            wanted = self.options.overrides.get(name) or request_for_offers(offers)
            type_hash = next((str(p.topic_type_hash) for p in publishers if str(p.topic_type_hash)), "") or (
                type_hash_of(type_name))
            topic = Topic(name, type_name, "cdr", offers, type_hash)
            writer.add_topic(topic, definition(type_name))
            if name in self.options.write.repeat_transient_local and wanted["durability"] != "transient_local":
                self._warn(f"topic {name} is repeated in each file (--repeat-transient-local) but not every "
                           "publisher offers it transient local: a late recorder may miss its messages")
            receiver.subscribe(name, cls, name, profile(wanted, depth=None if name in self.options.overrides
                                                       else RECEIVE_DEPTH))
            self._subscribed[name] = TopicStats()
            depth = self.options.write.repeat_depth(topic)
            repeated = f" (repeat-transient-local, depth={depth})" if depth else ""
            self._report(f"Subscribed to topic '{name}'{repeated}")

    def _write(self, writer: BagWriter, batch: list) -> None:
        for key, data, info in batch:
            if key == CLOCK_KEY:
                self._clock = _clock_ns(data)
                continue
            stats = self._subscribed[key]
            stats.received += 1
            sequence, gid = info["publication_sequence_number"], info["gid"]
            if sequence is not None:
                previous = stats.last_sequence.get(gid)
                if previous is not None and sequence > previous + 1:
                    stats.lost += sequence - previous - 1
                stats.last_sequence[gid] = sequence
            else:
                stats.unsequenced += 1
            if self.paused:
                self._paused_dropped += 1
                continue
            if self.options.use_sim_time:
                if self._clock is None:
                    self._before_clock_dropped += 1
                    continue
                log_time = self._clock
            else:
                log_time = info["received_timestamp"]
            writer.write(key, data, log_time, info["source_timestamp"])
            stats.written += 1

    def _drain(self, receiver: Receiver, writer: BagWriter) -> None:
        """Write what arrived before the stop: until nothing came for DRAIN_QUIET_SECONDS (the
        Receiver takes a message as soon as rcl has it), at most DRAIN_SECONDS."""
        deadline = time.monotonic() + DRAIN_SECONDS
        while time.monotonic() < deadline:
            batch = receiver.batch(DRAIN_QUIET_SECONDS)
            if not batch:
                return
            self._write(writer, batch)

    def run(self) -> Result:
        options = self.options
        writer = BagWriter(options.uri, options.write)
        error = None
        graph = Graph()
        receiver = Receiver(graph.node)
        try:
            if options.use_sim_time:
                receiver.subscribe(CLOCK_KEY, message_class("rosgraph_msgs/msg/Clock"), CLOCK_TOPIC,
                                   profile({**default_profile(), "reliability": "best_effort"}, RECEIVE_DEPTH))
            self._report("Listening for topics...")
            if self.paused:
                self._report("Recording is paused (press space to resume).")
            next_poll = next_flush = time.monotonic()
            while not self._stopping:
                now = time.monotonic()
                if now >= next_poll:
                    self._discover(graph, receiver, writer)
                    next_poll = now + options.polling_interval
                if now >= next_flush:
                    writer.flush()
                    next_flush = now + FLUSH_SECONDS
                self._write(writer, receiver.batch(min(0.05, options.polling_interval)))
            self._drain(receiver, writer)
        except DiskFull as full:
            error = str(full)
        except RocError as failure:
            error = str(failure)
        finally:
            receiver.close()
            try:
                metadata = writer.close()
            except DiskFull as full:
                error = error or str(full)
                metadata = writer.metadata()
            graph.close()
        return Result(metadata, self._subscribed, self._paused_dropped, self._before_clock_dropped, error,
                      writer.repeated)
