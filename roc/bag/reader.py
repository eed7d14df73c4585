"""Opening a bag for reading: a bag directory (``metadata.yaml`` and its files), a directory whose
recording was killed before it wrote ``metadata.yaml``, or a bare ``.mcap`` / ``.db3`` file (either
possibly ``.zstd``-compressed). Messages of several files come out in one time order."""

from __future__ import annotations

import heapq
import re
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path

from roc.bag import compression
from roc.bag.mcap_storage import EXTENSION as MCAP_EXTENSION
from roc.bag.mcap_storage import McapFile
from roc.bag.message import Definition, FileSummary, Message
from roc.bag.metadata import (
    METADATA_FILE,
    BagError,
    BagMetadata,
    FileInfo,
    Topic,
    directory_size,
    from_document,
    read_metadata,
)
from roc.bag.sqlite_storage import EXTENSION as SQLITE_EXTENSION
from roc.bag.sqlite_storage import SqliteFile

STORAGES = {"mcap": MCAP_EXTENSION, "sqlite3": SQLITE_EXTENSION}
_MAGIC = {b"\x89MCAP0\r\n": "mcap", b"SQLite format 3\x00": "sqlite3"}
StorageFile = McapFile | SqliteFile


def storage_of(path: Path) -> str | None:
    """The storage of a file, from its extension, else from its first bytes."""
    name = path.name[:-len(compression.SUFFIX)] if path.name.endswith(compression.SUFFIX) else path.name
    for storage, extension in STORAGES.items():
        if name.endswith(extension):
            return storage
    try:
        with open(path, "rb") as handle:
            head = handle.read(16)
    except OSError:
        return None
    return next((storage for magic, storage in _MAGIC.items() if head.startswith(magic)), None)


def _split_index(path: Path) -> tuple:
    """Sort key of a split file: its name with numbers compared as numbers (bag_2 before bag_10)."""
    return tuple(int(part) if part.isdigit() else part for part in re.split(r"(\d+)", path.name))


def check_storage(storage: str | None, where: str) -> None:
    if storage is not None and storage not in STORAGES:
        raise BagError(f"{where}: unknown storage '{storage}' (roc reads and writes: {', '.join(STORAGES)})")


def metadata_from_summaries(storage: str, summaries: list[tuple[str, FileSummary]]) -> BagMetadata:
    """A bag's metadata built from its files (what ``reindex`` writes): topics in order of first
    appearance, counts added up, the time span of all files. Compression and the ROS distribution
    come from rosbag2's metadata kept inside the files, when there is some."""
    topics: dict[str, Topic] = {}
    counts: dict[str, int] = {}
    files = []
    embedded: BagMetadata | None = None
    for relative, summary in summaries:
        for topic in summary.topics:
            topics.setdefault(topic.name, topic)
            counts[topic.name] = counts.get(topic.name, 0) + summary.counts.get(topic.name, 0)
        files.append(FileInfo(path=relative, starting_time=summary.start, duration=summary.end - summary.start,
                              message_count=summary.message_count))
        if summary.bag_metadata and embedded is None:
            try:
                import yaml

                embedded = from_document(yaml.safe_load(summary.bag_metadata), relative)
            except Exception:  # noqa: BLE001 - damaged embedded metadata is only a hint
                embedded = None
    with_messages = [f for f in files if f.message_count]
    start = min((f.starting_time for f in with_messages), default=0)
    end = max((f.starting_time + f.duration for f in with_messages), default=0)
    compressed = any(path.endswith(compression.SUFFIX) for path, _ in summaries)
    return BagMetadata(
        storage_identifier=storage, relative_file_paths=[path for path, _ in summaries], files=files,
        duration=end - start, starting_time=start, message_count=sum(f.message_count for f in files),
        topics=[(topic, counts[name]) for name, topic in topics.items()],
        compression_format="zstd" if compressed else (embedded.compression_format if embedded else ""),
        compression_mode="file" if compressed else (embedded.compression_mode if embedded else ""),
        custom_data=embedded.custom_data if embedded else {}, ros_distro=embedded.ros_distro if embedded else "")


class RepeatedCopies:
    """Tells the copies that a split recording begins each file with (``--repeat-transient-local``, roc's or
    rosbag2's) from the original messages: a message of a transient local topic, logged at the start time of
    a file after the first, whose bytes are those of a message of the topic met before it. Called on
    each message of one pass over the bag, in time order: a copy whose original came before the pass's
    start is no copy for it (a playback that starts in the middle of the bag needs it)."""

    def __init__(self, bag: Bag) -> None:
        self.topics = {topic.name for topic in bag.topics() if topic.transient_local}
        self.file_starts = {f.starting_time for f in bag.metadata.files[1:] if f.message_count}
        self.seen: dict[str, set[bytes]] = {}  # of the transient local topics: few messages each

    @property
    def possible(self) -> bool:
        return bool(self.topics and self.file_starts)

    def __call__(self, message: Message) -> bool:
        if message.topic not in self.topics:
            return False
        seen = self.seen.setdefault(message.topic, set())
        if message.log_time in self.file_starts and message.data in seen:
            return True
        seen.add(message.data)
        return False


def repeated_copies(bag: Bag) -> dict[str, int]:
    """How many of each topic's messages are copies a split recording repeated (RepeatedCopies)."""
    is_copy = RepeatedCopies(bag)
    counted: dict[str, int] = {}
    if is_copy.possible:
        for message in bag.messages(sorted(is_copy.topics)):
            if is_copy(message):
                counted[message.topic] = counted.get(message.topic, 0) + 1
    return counted


class Bag:
    """A bag opened for reading; ``storage`` forces the storage (else found from the files)."""

    def __init__(self, path: Path | str, storage: str | None = None) -> None:
        self.path = Path(path)
        check_storage(storage, "--storage")
        self._temporary: tempfile.TemporaryDirectory | None = None
        self._open: dict[str, StorageFile] = {}
        self.metadata_missing = False  # a directory without metadata.yaml: read from its files
        if not self.path.exists():
            raise BagError(f"{self.path}: no such file or directory")
        if self.path.is_dir():
            self.directory = self.path
            if (self.path / METADATA_FILE).is_file():
                self.metadata = read_metadata(self.path)
                check_storage(self.metadata.storage_identifier, str(self.path / METADATA_FILE))
                self.storage = storage or self.metadata.storage_identifier
                self.files = [self._resolve(p) for p in self.metadata.relative_file_paths]
            else:
                self.files = sorted((p for p in self.path.iterdir() if p.is_file() and storage_of(p)), key=_split_index)
                if not self.files:
                    raise BagError(f"{self.path}: not a bag (no {METADATA_FILE} and no .mcap or .db3 file)")
                self.storage = storage or storage_of(self.files[0]) or "mcap"
                self.metadata_missing = True
                self.metadata = self._metadata_from_files()
        else:
            self.directory = self.path.parent
            found = storage or storage_of(self.path)
            if found is None:
                raise BagError(f"{self.path}: not a bag file (neither MCAP nor sqlite3; roc reads .mcap and .db3)")
            self.storage = found
            self.files = [self.path]
            self.metadata = self._metadata_from_files()
        self._decompress = (compression.MessageDecompressor(str(self.path))
                            if self.metadata.compression_mode.lower() == "message" else None)

    def _resolve(self, relative: str) -> Path:
        """A file named in metadata.yaml (old bags name it with the bag directory in front)."""
        for candidate in (self.path / relative, self.path / Path(relative).name):
            if candidate.is_file():
                return candidate
        raise BagError(f"{self.path / relative}: missing (named in {self.path / METADATA_FILE})")

    def _metadata_from_files(self) -> BagMetadata:
        summaries = [(self._relative(path), self.file(path).summary()) for path in self.files]
        metadata = metadata_from_summaries(self.storage, summaries)
        metadata.bag_size = directory_size(self.path) if self.path.is_dir() else self.path.stat().st_size
        return metadata

    def _relative(self, path: Path) -> str:
        return path.name

    @property
    def incomplete_files(self) -> list[Path]:
        """Files that were not closed (their recording was killed); a compressed file was closed before."""
        return [p for p in self.files
                if not p.name.endswith(compression.SUFFIX) and not getattr(self.file(p), "complete", True)]

    def file(self, path: Path) -> StorageFile:
        """The opened storage file ``path`` (decompressed into a temporary directory first if .zstd)."""
        key = str(path)
        if key not in self._open:
            readable = path
            if path.name.endswith(compression.SUFFIX):
                if self._temporary is None:
                    self._temporary = tempfile.TemporaryDirectory(prefix="roc-bag-")
                readable = compression.decompress_file(
                    path, Path(self._temporary.name) / path.name[:-len(compression.SUFFIX)])
            reader: StorageFile = McapFile(readable) if self.storage == "mcap" else SqliteFile(readable)
            self._open[key] = reader
        return self._open[key]

    def _release(self, path: Path) -> None:
        opened = self._open.pop(str(path), None)
        if opened is not None:
            opened.close()
            if self._temporary is not None and opened.path.parent == Path(self._temporary.name):
                opened.path.unlink(missing_ok=True)

    def topics(self) -> list[Topic]:
        return [topic for topic, _ in self.metadata.topics]

    def definitions(self) -> dict[str, Definition]:
        """The full definitions the files hold, by type (empty for a storage that keeps none)."""
        found: dict[str, Definition] = {}
        for path in self.files:
            for type_name, definition in self.file(path).summary().definitions.items():
                found.setdefault(type_name, definition)
            if all(topic.type in found for topic in self.topics()):
                break
        return found

    def _groups(self) -> list[list[Path]]:
        """Files in groups whose time spans overlap, in time order: each group is merged, the groups
        are read one after the other (so only one compressed file of a split bag is unpacked at once)."""
        spans = {f.path: (f.starting_time, f.starting_time + f.duration) for f in self.metadata.files
                 if f.message_count}
        if len(spans) != len(self.files) and len(self.files) > 1:
            return [list(self.files)]
        ordered = sorted(self.files, key=lambda p: spans.get(self._relative(p), spans.get(p.name, (0, 0))))
        groups: list[list[Path]] = []
        group_end = None
        for path in ordered:
            start, end = spans.get(self._relative(path), spans.get(path.name, (0, 0)))
            if groups and group_end is not None and start <= group_end:
                groups[-1].append(path)
                group_end = max(group_end, end)
            else:
                groups.append([path])
                group_end = end
        return groups

    def messages(self, topics: Iterable[str] | None = None, start: int | None = None,
                 end: int | None = None) -> Iterator[Message]:
        """Every message (of ``topics``, with log time in [start, end]) in log time order."""
        wanted = list(topics) if topics is not None else None
        for group in self._groups():
            streams = [self.file(path).messages(wanted, start, end) for path in group]
            merged = streams[0] if len(streams) == 1 else heapq.merge(*streams, key=lambda m: m.log_time)
            for message in merged:
                if self._decompress is not None:
                    message = message._replace(data=self._decompress(message.data))
                yield message
            for path in group:
                self._release(path)

    def close(self) -> None:
        for path in list(self._open):
            self._release(Path(path))
        if self._temporary is not None:
            self._temporary.cleanup()
            self._temporary = None

    def __enter__(self) -> Bag:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
