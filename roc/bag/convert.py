"""``roc bag convert``: input bags rewritten into output bags as rosbag2's output-options YAML
describes them (``output_bags``: each a uri with StorageOptions and RecordOptions: storage, split
sizes and durations, compression, topic and service selection, ``start_time_ns``/``end_time_ns``,
``repeat_transient_local_messages`` and ``repeat_all_transient_local_depth`` as rosbag2 names them).
Per topic, an output may also keep a range of messages (``topic_message_ranges``: first and last
index, counted from 0 over the inputs, as ros2/rosbag2#2500 proposes) or of log times
(``topic_time_ranges``: first and last nanosecond). The inputs are read once, merged in time order,
and each message goes to every output that takes it. Definitions come from the input bags, else from
the environment."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from roc.bag.definitions import definition as installed_definition
from roc.bag.message import Definition
from roc.bag.metadata import BagError, BagMetadata, Topic
from roc.bag.reader import Bag
from roc.bag.selection import Selection
from roc.bag.writer import DEFAULT_STORAGE, BagWriter, WriteOptions, check_options
from roc.errors import UsageError

_LISTS = ("topics", "topic_types", "services", "exclude_topics", "exclude_topic_types", "exclude_services")
_KNOWN = {"uri", "storage_id", "max_bagfile_size", "max_bagfile_duration", "max_cache_size", "storage_preset_profile",
          "storage_config_uri", "snapshot_mode", "start_time_ns", "end_time_ns", "custom_data", "all", "all_topics",
          "all_services", "is_discovery_disabled", "rmw_serialization_format", "topic_polling_interval", "regex",
          "exclude", "exclude_regex", "node_prefix", "compression_mode", "compression_format",
          "compression_queue_size", "compression_threads", "compression_threads_priority",
          "topic_qos_profile_overrides", "include_hidden_topics", "include_unpublished_topics", "ignore_leaf_topics",
          "start_paused", "use_sim_time", "disable_keyboard_controls", "repeat_transient_local_messages",
          "repeat_all_transient_local_depth", "topic_message_ranges", "topic_time_ranges", *_LISTS}
Range = tuple[int, int]  # first and last, both kept


@dataclass
class Output:
    uri: Path
    options: WriteOptions
    selection: Selection
    start: int | None
    end: int | None
    where: str = ""  # the output's place in its YAML file, for errors
    message_ranges: dict[str, Range] = field(default_factory=dict)
    time_ranges: dict[str, Range] = field(default_factory=dict)

    def keeps(self, topic: str, index: int, log_time: int) -> bool:
        """Whether the message ``index`` of ``topic`` (counted over the inputs) is in its ranges."""
        first, last = self.message_ranges.get(topic, (0, index))
        start, end = self.time_ranges.get(topic, (log_time, log_time))
        return first <= index <= last and start <= log_time <= end


def _integer(value: Any, where: str, least: int = 0) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < least:
        raise UsageError(f"{where}: expected a{' positive' if least else ' non-negative'} integer, got {value!r}")
    return value


def _ranges(entry: dict, key: str, where: str) -> dict[str, Range]:
    """``{topic: [first, last]}`` (or ``{first, last}``) of ``entry[key]``."""
    given = entry.get(key) or {}
    if not isinstance(given, dict):
        raise UsageError(f"{where}: {key} must map topic names to [first, last]")
    ranges = {}
    for topic, bounds in given.items():
        at = f"{where}: {key}: {topic}"
        if isinstance(bounds, dict) and set(bounds) == {"first", "last"}:
            bounds = [bounds["first"], bounds["last"]]
        if not isinstance(bounds, list) or len(bounds) != 2:
            raise UsageError(f"{at}: expected [first, last]")
        first, last = _integer(bounds[0], at), _integer(bounds[1], at)
        if first > last:
            raise UsageError(f"{at}: the first ({first}) is after the last ({last})")
        ranges[str(topic)] = (first, last)
    return ranges


def _repeat(entry: dict, where: str) -> tuple[dict[str, int], int]:
    """rosbag2's ``repeat_transient_local_messages`` ({topic: depth}) and
    ``repeat_all_transient_local_depth``."""
    given = entry.get("repeat_transient_local_messages") or {}
    if not isinstance(given, dict):
        raise UsageError(f"{where}: repeat_transient_local_messages must map topic names to depths")
    depths = {str(topic): _integer(depth, f"{where}: repeat_transient_local_messages: {topic}", least=1)
              for topic, depth in given.items()}
    every = _integer(entry.get("repeat_all_transient_local_depth") or 0, f"{where}: repeat_all_transient_local_depth")
    return depths, every


def _output(entry: Any, where: str) -> Output:
    if not isinstance(entry, dict) or not entry.get("uri"):
        raise UsageError(f"{where}: each output bag needs a uri")
    unknown = sorted(set(entry) - _KNOWN)
    if unknown:
        raise UsageError(f"{where}: unknown key '{unknown[0]}'")
    for key in _LISTS:
        if entry.get(key) is not None and not isinstance(entry[key], list):
            raise UsageError(f"{where}: {key} must be a list")
    every = bool(entry.get("all"))
    mode = str(entry.get("compression_mode") or "none").lower()
    repeated, repeat_all = _repeat(entry, where)
    options = WriteOptions(storage=str(entry.get("storage_id") or DEFAULT_STORAGE),
                           max_bag_size=int(entry.get("max_bagfile_size") or 0),
                           max_bag_duration=int(entry.get("max_bagfile_duration") or 0) * 1_000_000_000,
                           compression_mode=mode, compression_format=str(entry.get("compression_format") or ""),
                           preset=str(entry.get("storage_preset_profile") or "none"),
                           custom_data={str(k): str(v) for k, v in (entry.get("custom_data") or {}).items()},
                           repeat_transient_local=repeated, repeat_all_transient_local=repeat_all)
    try:
        check_options(options)
        selection = Selection(
            all_topics=every or bool(entry.get("all_topics")), all_services=every or bool(entry.get("all_services")),
            regex=str(entry.get("regex") or ""),
            exclude_regex=str(entry.get("exclude_regex") or entry.get("exclude") or ""),
            include_hidden_topics=bool(entry.get("include_hidden_topics")),
            **{key: [str(v) for v in entry.get(key) or []] for key in _LISTS})
    except UsageError as error:
        raise UsageError(f"{where}: {error}") from None
    start, end = int(entry.get("start_time_ns", -1)), int(entry.get("end_time_ns", -1))
    return Output(Path(str(entry["uri"])), options, selection, start if start >= 0 else None,
                  end if end >= 0 else None, where, _ranges(entry, "topic_message_ranges", where),
                  _ranges(entry, "topic_time_ranges", where))


def read_output_options(path: Path) -> list[Output]:
    from roc.fsutil import read_yaml

    document = read_yaml(path)
    bags = document.get("output_bags") if isinstance(document, dict) else None
    if not isinstance(bags, list) or not bags:
        raise UsageError(f"{path}: expected a top-level key 'output_bags' with a list of output bags")
    outputs = [_output(entry, f"{path}: output_bags[{i}]") for i, entry in enumerate(bags)]
    for output in outputs:
        if output.uri.exists():
            raise UsageError(f"{path}: output bag '{output.uri}' already exists")
    return outputs


def _topics(bags: list[Bag]) -> tuple[dict[str, Topic], dict[str, Definition]]:
    """Every input topic (one type per name) and the definition of each type."""
    topics: dict[str, Topic] = {}
    definitions: dict[str, Definition] = {}
    for bag in bags:
        for topic in bag.topics():
            known = topics.setdefault(topic.name, topic)
            if known.type != topic.type:
                raise BagError(f"{bag.path}: topic {topic.name} has type {topic.type}, another input {known.type}")
        for type_name, found in bag.definitions().items():
            if found.encoding != "unknown":
                definitions.setdefault(type_name, found)
    for topic in topics.values():
        if topic.type not in definitions:
            definitions[topic.type] = installed_definition(topic.type)
    return topics, definitions


def _check_ranges(outputs: list[Output], counts: dict[str, int]) -> None:
    """A UsageError for a range of a topic the inputs lack, or past its last message (as rosbag2#2500)."""
    for output in outputs:
        for key, ranges in (("topic_message_ranges", output.message_ranges), ("topic_time_ranges", output.time_ranges)):
            for topic, (_, last) in ranges.items():
                if topic not in counts:
                    raise UsageError(f"{output.where}: {key}: {topic}: no input bag has this topic")
                if key == "topic_message_ranges" and last >= counts[topic]:
                    raise UsageError(f"{output.where}: {key}: {topic}: message {last} is past the last one "
                                     f"(the inputs hold {counts[topic]}, numbered from 0)")


def convert(inputs: list[tuple[str, str | None]], outputs: list[Output]) -> list[BagMetadata]:
    """Write every output bag; returns their metadata."""
    import heapq

    bags = []
    try:
        for uri, storage in inputs:
            bags.append(Bag(uri, storage))
        topics, definitions = _topics(bags)
        counts: dict[str, int] = {}
        for bag in bags:
            for topic, count in bag.metadata.topics:
                counts[topic.name] = counts.get(topic.name, 0) + count
        _check_ranges(outputs, counts)
        writers: list[tuple[Output, BagWriter, set[str]]] = []
        for output in outputs:
            writer = BagWriter(output.uri, output.options)
            taken = {name for name, topic in topics.items() if output.selection.takes(name, topic.type)}
            for name in sorted(taken, key=list(topics).index):
                writer.add_topic(topics[name], definitions[topics[name].type])
            writers.append((output, writer, taken))
        streams = [bag.messages() for bag in bags]
        merged = streams[0] if len(streams) == 1 else heapq.merge(*streams, key=lambda m: m.log_time)
        indices = dict.fromkeys(topics, 0)  # the next message's index, per topic
        for message in merged:
            index = indices[message.topic]
            indices[message.topic] += 1
            for output, writer, taken in writers:
                if message.topic not in taken or not output.keeps(message.topic, index, message.log_time):
                    continue
                if output.start is not None and message.log_time < output.start:
                    writer.remember(message.topic, message.data, message.log_time, message.publish_time)
                elif output.end is None or message.log_time <= output.end:
                    writer.write(message.topic, message.data, message.log_time, message.publish_time)
        return [writer.close() for _, writer, _ in writers]
    finally:
        for bag in bags:
            bag.close()
