"""rosbag2's MCAP storage through the ``mcap`` library: profile ``ros2``, a schema per type (its
full definition, ``ros2msg``), a channel per topic (``cdr``, with ``offered_qos_profiles`` and
``topic_type_hash`` metadata), chunks with indexes and a summary, and rosbag2's serialised metadata
in a ``rosbag2`` metadata record.

A file whose recording was killed has no summary: it is read record by record up to where it ends
(every whole chunk), which is also how ``roc bag reindex`` recovers it."""

from __future__ import annotations

import io
import os
import struct
from collections.abc import Iterable, Iterator
from pathlib import Path

import yaml
from mcap.exceptions import McapError
from mcap.reader import SeekingReader
from mcap.records import Channel, Chunk, Metadata, Schema
from mcap.records import Message as McapMessage
from mcap.stream_reader import StreamReader, breakup_chunk

from roc import __version__
from roc.bag.message import Definition, FileSummary, Message
from roc.bag.metadata import BagError, Topic
from roc.bag.qos import dump_profiles, parse_profiles

EXTENSION = ".mcap"
CHUNK_SIZE = 768 * 1024  # libmcap's default, as rosbag2 writes
PRESETS = {  # rosbag2_storage_mcap's preset profiles
    "none": "Default writer configuration.",
    "fastwrite": "Disables CRC and chunking for faster writing.",
    "zstd_fast": "Use Zstd chunk compression on Fastest level.",
    "zstd_small": "Use Zstd chunk compression on Slowest level, for smallest file size.",
}
MESSAGE_OVERHEAD = 31  # bytes of an MCAP message record besides its data (opcode, length, header)
# What a damaged file raises while it is read.
READ_ERRORS = (McapError, struct.error, ValueError, EOFError, KeyError, IndexError, MemoryError, OSError)


def _topic(channel: Channel, schema: Schema | None) -> Topic:
    try:
        profiles = parse_profiles(channel.metadata.get("offered_qos_profiles", ""))
    except (ValueError, yaml.YAMLError):
        profiles = []
    return Topic(name=channel.topic, type=schema.name if schema else "", serialization_format=channel.message_encoding,
                 offered_qos_profiles=profiles, type_description_hash=channel.metadata.get("topic_type_hash", ""))


def _definition(schema: Schema, type_hash: str) -> Definition:
    return Definition(type=schema.name, encoding=schema.encoding or "unknown",
                      text=bytes(schema.data).decode("utf-8", "replace"), type_hash=type_hash)


class McapFile:
    """One MCAP file of a bag, for reading."""

    def __init__(self, path: Path) -> None:
        self.path = path
        try:
            self._file = open(path, "rb")  # noqa: SIM115 - closed by close()
        except OSError as error:
            raise BagError(f"{path}: cannot open it ({error.strerror})") from None
        try:
            self._reader = SeekingReader(self._file)
        except READ_ERRORS:
            self._file.close()
            raise BagError(f"{path}: not an MCAP file (no MCAP magic at its start)") from None
        try:
            self._summary = self._reader.get_summary()
        except READ_ERRORS:
            self._summary = None  # not closed: no footer, or a damaged summary
            try:
                self._reader.get_header()
            except READ_ERRORS:
                self._file.close()
                raise BagError(f"{path}: a damaged or truncated MCAP file (not even its header is whole)") from None

    def close(self) -> None:
        self._file.close()

    @property
    def complete(self) -> bool:
        return self._summary is not None and self._summary.statistics is not None

    def summary(self) -> FileSummary:
        """From the summary section when the file has one, else by reading the file to its end."""
        if not self.complete:
            return self._scan()
        summary = self._summary
        assert summary is not None and summary.statistics is not None
        statistics = summary.statistics
        topics: list[Topic] = []
        counts: dict[str, int] = {}
        definitions: dict[str, Definition] = {}
        for channel_id, channel in sorted(summary.channels.items()):
            schema = summary.schemas.get(channel.schema_id)
            topic = _topic(channel, schema)
            topics.append(topic)
            counts[topic.name] = counts.get(topic.name, 0) + statistics.channel_message_counts.get(channel_id, 0)
            if schema is not None:
                definitions.setdefault(schema.name, _definition(schema, topic.type_description_hash))
        return FileSummary(topics=topics, counts=counts, start=statistics.message_start_time,
                           end=statistics.message_end_time, message_count=statistics.message_count,
                           definitions=definitions, bag_metadata=self._bag_metadata())

    def _bag_metadata(self) -> str:
        try:
            for record in self._reader.iter_metadata():
                if record.name == "rosbag2":
                    return record.metadata.get("serialized_metadata", "")
        except READ_ERRORS:
            pass
        return ""

    def _records(self) -> Iterator:
        """Every record from the start, chunks opened, up to where a damaged file ends."""
        self._file.seek(0)
        try:
            for record in StreamReader(self._file, emit_chunks=True).records:
                if isinstance(record, Chunk):
                    yield from breakup_chunk(record)
                else:
                    yield record
        except READ_ERRORS:
            return

    def _scan(self) -> FileSummary:
        schemas: dict[int, Schema] = {}
        channels: dict[int, Channel] = {}
        counts: dict[str, int] = {}
        start = end = count = 0
        bag_metadata = ""
        for record in self._records():
            if isinstance(record, McapMessage):
                channel = channels.get(record.channel_id)
                if channel is None:
                    continue
                counts[channel.topic] = counts.get(channel.topic, 0) + 1
                start = record.log_time if not count else min(start, record.log_time)
                end = max(end, record.log_time)
                count += 1
            elif isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                channels[record.id] = record
            elif isinstance(record, Metadata) and record.name == "rosbag2":
                bag_metadata = record.metadata.get("serialized_metadata", "")
        topics: list[Topic] = []
        definitions: dict[str, Definition] = {}
        for channel in channels.values():
            schema = schemas.get(channel.schema_id)
            topic = _topic(channel, schema)
            topics.append(topic)
            counts.setdefault(topic.name, 0)
            if schema is not None:
                definitions.setdefault(schema.name, _definition(schema, topic.type_description_hash))
        return FileSummary(topics=topics, counts=counts, start=start, end=end, message_count=count,
                           definitions=definitions, bag_metadata=bag_metadata, complete=False)

    def messages(self, topics: Iterable[str] | None = None, start: int | None = None,
                 end: int | None = None) -> Iterator[Message]:
        """Messages in log time order (file order for a file that was not closed), within
        [start, end] and of ``topics`` (all when None)."""
        wanted = set(topics) if topics is not None else None
        if not self.complete:
            yield from self._scan_messages(wanted, start, end)
            return
        try:
            for _, channel, record in self._reader.iter_messages(
                    topics=list(wanted) if wanted is not None else None, starting_at=start, ending_at=end,
                    log_time_order=True):
                yield Message(channel.topic, record.data, record.log_time, record.publish_time)
        except READ_ERRORS as error:
            raise BagError(f"{self.path}: damaged MCAP data ({type(error).__name__}: {error})") from None

    def _scan_messages(self, wanted: set[str] | None, start: int | None, end: int | None) -> Iterator[Message]:
        channels: dict[int, str] = {}
        for record in self._records():
            if isinstance(record, Channel):
                channels[record.id] = record.topic
            elif isinstance(record, McapMessage):
                topic = channels.get(record.channel_id)
                if topic is None or (wanted is not None and topic not in wanted):
                    continue
                if (start is not None and record.log_time < start) or (end is not None and record.log_time > end):
                    continue
                yield Message(topic, record.data, record.log_time, record.publish_time)


class _Unbuffered:
    """The file the MCAP writer writes to, without a buffer of Python's: each record (a whole chunk
    when chunked) reaches the operating system when written, so a killed recorder loses only the
    chunk it was filling."""

    def __init__(self, path: Path) -> None:
        self._raw = io.FileIO(path, "xb")
        self._position = 0

    def write(self, data) -> int:
        view = memoryview(data)
        while view:
            written = self._raw.write(view)
            view = view[written:]
            self._position += written
        return len(data)

    def tell(self) -> int:
        return self._position

    def flush(self) -> None:
        pass

    def close(self) -> None:
        self._raw.close()


class McapWriter:
    """One MCAP file being written (rosbag2's layout); ``preset``: one of PRESETS."""

    def __init__(self, path: Path, preset: str = "none") -> None:
        self.path = path
        try:
            self._file = _Unbuffered(path)
        except OSError as error:
            raise BagError(f"{path}: cannot create it ({error.strerror})") from None
        from mcap.writer import CompressionType, Writer  # here: it loads importlib.metadata, 40 ms a reader spares

        chunked = preset != "fastwrite"
        compression = CompressionType.ZSTD if preset.startswith("zstd") else CompressionType.NONE
        self._writer = Writer(self._file,  # type: ignore[arg-type]  # a stream is anything with write and tell
                              chunk_size=4 * 1024 * 1024 if preset == "zstd_small" else CHUNK_SIZE,
                              compression=compression, use_chunking=chunked,
                              enable_crcs=preset == "zstd_small")  # rosbag2 writes no chunk CRCs but there
        self._writer.start(profile="ros2", library=f"roc {__version__}")
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._chunk_bytes = 0  # messages added since the file last grew (the chunk being filled)
        self._file_bytes = 0

    def add_topic(self, topic: Topic, definition: Definition) -> None:
        if topic.name in self._channels:
            return
        schema_id = self._schemas.get(topic.type)
        if schema_id is None:
            schema_id = self._writer.register_schema(topic.type, definition.encoding, definition.text.encode())
            self._schemas[topic.type] = schema_id
        self._channels[topic.name] = self._writer.register_channel(
            topic.name, topic.serialization_format, schema_id,
            {"offered_qos_profiles": dump_profiles(topic.offered_qos_profiles),
             "topic_type_hash": topic.type_description_hash})

    def write(self, topic: str, data: bytes, log_time: int, publish_time: int) -> None:
        self._writer.add_message(self._channels[topic], log_time, data, publish_time)
        if self._file.tell() != self._file_bytes:
            self._file_bytes, self._chunk_bytes = self._file.tell(), 0
        else:
            self._chunk_bytes += len(data) + MESSAGE_OVERHEAD

    def size(self) -> int:
        """Bytes written so far, the chunk being filled included."""
        return self._file.tell() + self._chunk_bytes

    def close(self, serialized_metadata: str) -> None:
        """Write rosbag2's metadata record, the summary and the footer."""
        try:
            self._writer.add_metadata("rosbag2", {"serialized_metadata": serialized_metadata})
            self._writer.finish()
            os.fsync(self._file._raw.fileno())
        finally:
            self._file.close()
