"""Writing a bag as rosbag2 does: a directory ``NAME`` with ``NAME_0.mcap`` (or ``.db3``),
``NAME_1...`` after each split (by size or duration), each file zstd-compressed when it is closed
(``file`` mode) or each message compressed (``message`` mode, sqlite3 only as in rosbag2), and
``metadata.yaml`` written at the end (and kept inside each file, as rosbag2's storages do).

Transient local topics may be repeated (rosbag2's ``--repeat-transient-local``): the writer keeps the
latest messages of each such topic and begins every new file with them, stamped with the time of the
message that opens the file, so each file plays alone (``/tf_static``, ``/map``). rosbag2 stamps them
with the previous file's last time; the next message's time keeps the files' time spans apart, so a
reader still reads split files one after the other."""

from __future__ import annotations

import errno
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path

from roc.bag import compression
from roc.bag.mcap_storage import PRESETS as MCAP_PRESETS
from roc.bag.mcap_storage import McapWriter
from roc.bag.message import Definition
from roc.bag.metadata import BagError, BagMetadata, FileInfo, Topic, dump, ros_distro, write_metadata
from roc.bag.reader import STORAGES, check_storage
from roc.bag.sqlite_storage import PRESETS as SQLITE_PRESETS
from roc.bag.sqlite_storage import SqliteWriter
from roc.errors import UsageError

DEFAULT_STORAGE = "mcap"  # as Jazzy
PRESETS = {"mcap": MCAP_PRESETS, "sqlite3": SQLITE_PRESETS}
MIN_SPLIT_SIZE = 86016  # rosbag2 refuses a smaller --max-bag-size
# Errors that mean the disk (or the file size limit) is full.
FULL_DISK = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)


class DiskFull(BagError):
    """No room left to write: the bag holds everything written before."""


@dataclass
class WriteOptions:
    storage: str = DEFAULT_STORAGE
    max_bag_size: int = 0  # bytes; 0: no split by size
    max_bag_duration: int = 0  # ns; 0: no split by duration
    compression_mode: str = "none"  # none, file, message
    compression_format: str = ""  # zstd
    preset: str = "none"
    custom_data: dict[str, str] = field(default_factory=dict)
    # Repeated at the start of each file: the latest N messages of these topics (rosbag2's
    # repeat_transient_local_messages), and of every topic offered transient local when N > 0
    # (rosbag2's repeat_all_transient_local_depth).
    repeat_transient_local: dict[str, int] = field(default_factory=dict)
    repeat_all_transient_local: int = 0

    def repeat_depth(self, topic: Topic) -> int:
        """How many of ``topic``'s latest messages begin each file (0: none)."""
        if topic.name in self.repeat_transient_local:
            return self.repeat_transient_local[topic.name]
        return self.repeat_all_transient_local if topic.transient_local else 0


def check_options(options: WriteOptions) -> None:
    """UsageError for options rosbag2 refuses too."""
    check_storage(options.storage, "--storage")
    if options.preset not in PRESETS[options.storage]:
        raise UsageError(f"--storage-preset-profile: '{options.preset}' is not a preset of {options.storage} "
                         f"(choose from {', '.join(PRESETS[options.storage])})")
    if options.compression_mode not in compression.MODES:
        raise UsageError(f"--compression-mode: '{options.compression_mode}' is not one of "
                         f"{', '.join(compression.MODES)}")
    if options.compression_format and options.compression_format not in compression.FORMATS:
        raise UsageError(f"--compression-format: '{options.compression_format}' is not supported (roc has zstd)")
    if options.compression_format and options.compression_mode == "none":
        raise UsageError("cannot specify a compression format without a compression mode (--compression-mode)")
    if options.compression_mode != "none" and not options.compression_format:
        raise UsageError("--compression-mode needs --compression-format zstd")
    if options.compression_mode == "message" and options.storage == "mcap":
        raise UsageError("MCAP does not support message compression (as in rosbag2): use --compression-mode file, "
                         "or --storage-preset-profile zstd_fast for compressed MCAP chunks")
    if 0 < options.max_bag_size < MIN_SPLIT_SIZE:
        raise UsageError(f"--max-bag-size must be at least {MIN_SPLIT_SIZE} bytes (as in rosbag2)")
    if options.max_bag_size < 0 or options.max_bag_duration < 0:
        raise UsageError("--max-bag-size and --max-bag-duration may not be negative")
    depths = [*options.repeat_transient_local.values(), options.repeat_all_transient_local]
    if any(isinstance(depth, bool) or not isinstance(depth, int) or depth < 0 for depth in depths) or any(
            depth == 0 for depth in options.repeat_transient_local.values()):
        raise UsageError("--repeat-transient-local: each depth must be a positive number of messages")


def _disk_error(error: OSError, path: Path) -> BagError:
    if error.errno in FULL_DISK:
        return DiskFull(f"{path}: the disk is full ({error.strerror}); the bag keeps what was written before")
    return BagError(f"{path}: cannot write ({error.strerror})")


def _failing(method):
    """A BagWriter method after whose failure the bag's metadata is taken from its files."""
    def wrapper(self, *args, **kwargs):
        try:
            return method(self, *args, **kwargs)
        except BagError:
            self.failed = True
            raise
    return wrapper


class BagWriter:
    """A bag being written into the new directory ``uri``."""

    def __init__(self, uri: Path | str, options: WriteOptions) -> None:
        check_options(options)
        self.uri = Path(uri)
        self.options = options
        if self.uri.exists():
            raise UsageError(f"output folder '{self.uri}' already exists")
        try:
            self.uri.mkdir(parents=True)
        except OSError as error:
            raise BagError(f"cannot create the bag folder '{self.uri}' ({error.strerror})") from None
        self._topics: dict[str, tuple[Topic, Definition]] = {}
        self._counts: dict[str, int] = {}
        self._files: list[FileInfo] = []
        self._paths: list[str] = []
        self._file: McapWriter | SqliteWriter | None = None
        self._file_start = self._file_end = self._file_count = 0
        self._latest: dict[str, deque[tuple[bytes, int, int]]] = {}  # of repeated topics, uncompressed
        self.repeated = 0  # messages written again at the start of a file
        self._compress = (compression.MessageCompressor() if options.compression_mode == "message" else None)
        self.closed = False
        self.failed = False  # a write failed: what the files hold may be less than what was written
        self._file = self._open_file()  # at once, as rosbag2: a recording in progress is a readable bag

    @property
    def message_count(self) -> int:
        return sum(self._counts.values())

    def _open_file(self) -> McapWriter | SqliteWriter:
        path = self.uri / f"{self.uri.name}_{len(self._paths)}{STORAGES[self.options.storage]}"
        writer_class = McapWriter if self.options.storage == "mcap" else SqliteWriter
        try:
            writer = writer_class(path, self.options.preset)
            for topic, definition in self._topics.values():
                writer.add_topic(topic, definition)
        except OSError as error:
            raise _disk_error(error, path) from None
        self._paths.append(path.name)
        self._file_start = self._file_end = self._file_count = 0
        return writer

    def add_topic(self, topic: Topic, definition: Definition) -> None:
        """Make ``topic`` writable (its definition stored once per type and file)."""
        if topic.name in self._topics:
            return
        self._topics[topic.name] = (topic, definition)
        self._counts.setdefault(topic.name, 0)
        depth = self.options.repeat_depth(topic)
        if depth:
            self._latest[topic.name] = deque(maxlen=depth)
        if self._file is not None:
            try:
                self._file.add_topic(topic, definition)
            except OSError as error:
                raise _disk_error(error, self._file.path) from None

    @_failing
    def write(self, topic: str, data: bytes, log_time: int, publish_time: int = 0) -> None:
        """One message of a topic added before; splits the bag first when a limit is reached."""
        if self._file is None:
            self._file = self._open_file()
        elif self._should_split(log_time):
            self.split()
            self._file = self._open_file()
        if not self._file_count:  # a new file begins with the repeated topics' latest messages
            kept = sorted(((kept_time, name, kept_data) for name, latest in self._latest.items()
                           for kept_data, kept_time, _ in latest), key=lambda item: item[0])
            for _, name, kept_data in kept:
                self._put(name, kept_data, log_time, log_time)
            self.repeated += len(kept)
        self._put(topic, data, log_time, publish_time)
        self.remember(topic, data, log_time, publish_time)

    def remember(self, topic: str, data: bytes, log_time: int, publish_time: int = 0) -> None:
        """Keep a message of a repeated topic for the start of the next file, without writing it
        (``convert`` remembers what comes before an output's start time)."""
        if topic in self._latest:
            self._latest[topic].append((data, log_time, publish_time))

    def _put(self, topic: str, data: bytes, log_time: int, publish_time: int) -> None:
        assert self._file is not None
        if self._compress is not None:
            data = self._compress(data)
        try:
            self._file.write(topic, data, log_time, publish_time)
        except OSError as error:
            raise _disk_error(error, self._file.path) from None
        self._counts[topic] += 1
        self._file_start = log_time if not self._file_count else min(self._file_start, log_time)
        self._file_end = max(self._file_end, log_time)
        self._file_count += 1

    def _should_split(self, log_time: int) -> bool:
        if not self._file_count or self._file is None:
            return False
        if self.options.max_bag_size and self._file.size() >= self.options.max_bag_size:
            return True
        return bool(self.options.max_bag_duration and log_time - self._file_start >= self.options.max_bag_duration)

    def flush(self) -> None:
        """Hand what is buffered to the storage (sqlite3 commits)."""
        if isinstance(self._file, SqliteWriter):
            try:
                self._file.flush()
            except OSError as error:
                raise _disk_error(error, self._file.path) from None

    @_failing
    def split(self) -> None:
        """Close the current file (compressing it in ``file`` mode); the next message opens a new one."""
        if self._file is None:
            return
        current = self._file
        self._file = None
        self._files.append(FileInfo(path=self._paths[-1], starting_time=self._file_start,
                                    duration=self._file_end - self._file_start, message_count=self._file_count))
        try:
            current.close(dump(self.metadata()))
            if self.options.compression_mode == "file":
                compressed = compression.compress_file(current.path)
                self._paths[-1] = compressed.name
                self._files[-1].path = compressed.name
        except OSError as error:
            raise _disk_error(error, current.path) from None

    def metadata(self) -> BagMetadata:
        files = list(self._files)
        if self._file is not None:
            files.append(FileInfo(path=self._paths[-1], starting_time=self._file_start,
                                  duration=self._file_end - self._file_start, message_count=self._file_count))
        with_messages = [f for f in files if f.message_count]
        start = min((f.starting_time for f in with_messages), default=0)
        end = max((f.starting_time + f.duration for f in with_messages), default=0)
        compressed = self.options.compression_mode != "none"
        return BagMetadata(
            storage_identifier=self.options.storage, relative_file_paths=list(self._paths), files=files,
            duration=end - start, starting_time=start, message_count=self.message_count,
            topics=[(topic, self._counts[name]) for name, (topic, _) in self._topics.items()],
            compression_format=self.options.compression_format if compressed else "",
            compression_mode=self.options.compression_mode if compressed else "",
            custom_data=dict(self.options.custom_data), ros_distro=ros_distro())

    def _readable_metadata(self) -> BagMetadata:
        """After a failed write: the metadata of what the files really hold (read back from them)."""
        from roc.bag.reader import Bag

        try:
            with Bag(self.uri, self.options.storage) as bag:
                return bag.metadata
        except BagError:
            return self.metadata()

    def close(self) -> BagMetadata:
        """Close the last file and write metadata.yaml."""
        if self.closed:
            return self.metadata()
        self.closed = True
        try:
            self.split()
        finally:
            metadata = self._readable_metadata() if self.failed else self.metadata()
            try:
                write_metadata(self.uri, metadata)
            except OSError as error:
                raise _disk_error(error, self.uri / "metadata.yaml") from None
        return metadata
