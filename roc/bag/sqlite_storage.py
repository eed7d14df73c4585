"""rosbag2's sqlite3 storage through the standard library: the ``topics``, ``messages`` and (schema
version 4, Jazzy's) ``schema``, ``metadata`` and ``message_definitions`` tables. Older files (no
schema table, fewer topic columns) are read too.

roc writes with a write-ahead log and commits every COMMIT_MESSAGES messages (or on ``flush``), so a
killed recording keeps every committed message; rosbag2's ``resilient`` preset asks for the same.

Reading writes nothing beside the file (``read_only_uri``): a read-only connection to a write-ahead-log
file would otherwise leave ``-shm`` and ``-wal`` files next to it, and could not open a file in a
read-only place at all."""

from __future__ import annotations

import sqlite3
import urllib.parse
from collections.abc import Iterable, Iterator
from pathlib import Path

import yaml

from roc.bag.message import Definition, FileSummary, Message
from roc.bag.metadata import BagError, Topic, ros_distro
from roc.bag.qos import dump_profiles, parse_profiles

EXTENSION = ".db3"
SCHEMA_VERSION = 4
COMMIT_MESSAGES = 1000
PRESETS = {  # rosbag2_storage_sqlite3's preset profiles
    "none": "Default profile, no special settings.",
    "resilient": "Avoid data corruption in case of crashes at the cost of performance.",
}
_CREATE = (
    "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL)",
    "CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL)",
    "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
    "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL, type_description_hash TEXT NOT NULL)",
    "CREATE TABLE message_definitions(id INTEGER PRIMARY KEY, topic_type TEXT NOT NULL, encoding TEXT NOT NULL, "
    "encoded_message_definition TEXT NOT NULL, type_description_hash TEXT NOT NULL)",
    "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
    "data BLOB NOT NULL)",
    "CREATE INDEX timestamp_idx ON messages (timestamp ASC)",
)


WAL_MODE = 2  # bytes 18 and 19 of a sqlite3 file's header: 2 in write-ahead-log mode


def _in_wal_mode(path: Path) -> bool:
    with open(path, "rb") as handle:
        header = handle.read(20)
    return len(header) == 20 and header[18] == header[19] == WAL_MODE


def _in_use(index: Path) -> bool:
    """Whether a connection holds a ``-shm`` index open: sqlite's connections keep a read lock on its
    byte 128 (the "DMS" byte) while they have it, so a recording still writing holds one."""
    import fcntl
    import os
    import struct

    try:
        descriptor = os.open(index, os.O_RDONLY)
    except OSError:
        return False
    try:
        flock = "hhqqi4x"  # struct flock: type, whence, start, length, pid
        answer = fcntl.fcntl(descriptor, fcntl.F_GETLK, struct.pack(flock, fcntl.F_WRLCK, 0, 128, 1, 0))
        return struct.unpack(flock, answer)[0] != fcntl.F_UNLCK
    except OSError:
        return True
    finally:
        os.close(descriptor)


def read_only_uri(path: Path) -> tuple[str, bool]:
    """The URI that opens ``path`` for reading without writing beside it, and whether the connection
    must then ask for exclusive locking. A file in rollback-journal mode opens read-only (``mode=ro``).
    A file in write-ahead-log mode that a recording is still writing shares its ``-shm`` index with
    it. Otherwise, without a log (or an empty one) the file alone holds everything and is read as
    ``immutable``; with one (a killed recording's last commits), the log is read with its index in
    this process's memory: exclusive locking before the first read (sqlite then neither creates a
    ``-shm`` nor writes one left behind), and no file locks (``unix-none``), since no writer is left."""
    base = "file:" + urllib.parse.quote(str(path.absolute())) + "?mode=ro"
    if not _in_wal_mode(path) or _in_use(path.with_name(path.name + "-shm")):
        return base, False
    log = path.with_name(path.name + "-wal")
    if not log.exists() or log.stat().st_size == 0:
        return base + "&immutable=1", False
    return base + "&vfs=unix-none", True


def _columns(connection: sqlite3.Connection, table: str) -> set[str]:
    return {row[1] for row in connection.execute(f"PRAGMA table_info({table})")}


class SqliteFile:
    """One sqlite3 file of a bag, for reading."""

    def __init__(self, path: Path) -> None:
        self.path = path
        if not path.is_file():
            raise BagError(f"{path}: no such file")
        try:
            uri, exclusive = read_only_uri(path)
            self._db = sqlite3.connect(uri, uri=True, check_same_thread=False)
            if exclusive:
                self._db.execute("PRAGMA locking_mode=EXCLUSIVE")
            tables = {row[0] for row in self._db.execute("SELECT name FROM sqlite_master WHERE type='table'")}
        except OSError as error:
            raise BagError(f"{path}: cannot read it ({error.strerror})") from None
        except sqlite3.DatabaseError as error:
            raise BagError(f"{path}: not a sqlite3 bag ({error})") from None
        if not {"topics", "messages"} <= tables:
            self._db.close()
            raise BagError(f"{path}: not a rosbag2 sqlite3 file (no topics and messages tables)")
        self._tables = tables
        self._topics = self._read_topics()

    def close(self) -> None:
        self._db.close()

    def _read_topics(self) -> dict[int, Topic]:
        columns = _columns(self._db, "topics")
        wanted = [c for c in ("offered_qos_profiles", "type_description_hash") if c in columns]
        extra = "".join(f", {column}" for column in wanted)
        query = f"SELECT id, name, type, serialization_format{extra} FROM topics ORDER BY id"
        topics = {}
        for row in self._query(query):
            values = dict(zip(wanted, row[4:]))
            try:
                profiles = parse_profiles(values.get("offered_qos_profiles", ""))
            except (ValueError, yaml.YAMLError):
                profiles = []
            topics[row[0]] = Topic(name=row[1], type=row[2], serialization_format=row[3],
                                   offered_qos_profiles=profiles,
                                   type_description_hash=values.get("type_description_hash") or "")
        return topics

    def _query(self, query: str, parameters: tuple = ()) -> list:
        try:
            return self._db.execute(query, parameters).fetchall()
        except sqlite3.DatabaseError as error:
            raise BagError(f"{self.path}: damaged sqlite3 file ({error})") from None

    def summary(self) -> FileSummary:
        counts = {topic.name: 0 for topic in self._topics.values()}
        for topic_id, count in self._query("SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id"):
            if topic_id in self._topics:
                counts[self._topics[topic_id].name] += count
        start, end = self._query("SELECT MIN(timestamp), MAX(timestamp) FROM messages")[0]
        definitions: dict[str, Definition] = {}
        if "message_definitions" in self._tables:
            for type_name, encoding, text, type_hash in self._query(
                    "SELECT topic_type, encoding, encoded_message_definition, type_description_hash "
                    "FROM message_definitions ORDER BY id"):
                definitions.setdefault(type_name, Definition(type_name, encoding, text, type_hash))
        bag_metadata = ""
        if "metadata" in self._tables:
            rows = self._query("SELECT metadata FROM metadata ORDER BY id DESC LIMIT 1")
            bag_metadata = rows[0][0] if rows else ""
        return FileSummary(topics=list(self._topics.values()), counts=counts, start=start or 0, end=end or 0,
                           message_count=sum(counts.values()), definitions=definitions, bag_metadata=bag_metadata)

    def messages(self, topics: Iterable[str] | None = None, start: int | None = None,
                 end: int | None = None) -> Iterator[Message]:
        """Messages in timestamp order (sqlite3 keeps no send time: ``publish_time`` is 0)."""
        names = {topic_id: topic.name for topic_id, topic in self._topics.items()}
        if topics is not None:
            wanted = set(topics)
            names = {topic_id: name for topic_id, name in names.items() if name in wanted}
        conditions, parameters = [f"topic_id IN ({','.join(str(i) for i in names) or 'NULL'})"], []
        if start is not None:
            conditions.append("timestamp >= ?")
            parameters.append(start)
        if end is not None:
            conditions.append("timestamp <= ?")
            parameters.append(end)
        query = (f"SELECT topic_id, timestamp, data FROM messages WHERE {' AND '.join(conditions)} "
                 "ORDER BY timestamp, id")
        try:
            for topic_id, timestamp, data in self._db.execute(query, parameters):
                yield Message(names[topic_id], bytes(data), timestamp, 0)
        except sqlite3.DatabaseError as error:
            raise BagError(f"{self.path}: damaged sqlite3 file ({error})") from None


class SqliteWriter:
    """One sqlite3 file being written (schema version 4)."""

    def __init__(self, path: Path, preset: str = "none") -> None:
        self.path = path
        if path.exists():
            raise BagError(f"{path}: already exists")
        try:
            self._db = sqlite3.connect(path, isolation_level=None, check_same_thread=False)
            self._db.execute("PRAGMA journal_mode=WAL")
            self._db.execute(f"PRAGMA synchronous={'NORMAL' if preset == 'resilient' else 'OFF'}")
            self._db.execute("BEGIN")
            for statement in _CREATE:
                self._db.execute(statement)
            self._db.execute("INSERT INTO schema (schema_version, ros_distro) VALUES (?, ?)",
                             (SCHEMA_VERSION, ros_distro()))
            self._db.execute("COMMIT")
        except sqlite3.Error as error:
            raise BagError(f"{path}: cannot create it ({error})") from None
        self._topics: dict[str, int] = {}
        self._types: set[str] = set()
        self._pending: list[tuple[int, int, bytes]] = []
        self._bytes = 0

    def add_topic(self, topic: Topic, definition: Definition) -> None:
        if topic.name in self._topics:
            return
        cursor = self._db.execute(
            "INSERT INTO topics (name, type, serialization_format, offered_qos_profiles, type_description_hash) "
            "VALUES (?, ?, ?, ?, ?)", (topic.name, topic.type, topic.serialization_format,
                                       dump_profiles(topic.offered_qos_profiles), topic.type_description_hash))
        self._topics[topic.name] = int(cursor.lastrowid or 0)
        if topic.type not in self._types:
            self._types.add(topic.type)
            self._db.execute("INSERT INTO message_definitions (topic_type, encoding, encoded_message_definition, "
                             "type_description_hash) VALUES (?, ?, ?, ?)",
                             (topic.type, definition.encoding, definition.text,
                              definition.type_hash or topic.type_description_hash))

    def write(self, topic: str, data: bytes, log_time: int, publish_time: int) -> None:
        self._pending.append((self._topics[topic], log_time, data))
        self._bytes += len(data) + 24
        if len(self._pending) >= COMMIT_MESSAGES:
            self.flush()

    def flush(self) -> None:
        if self._pending:
            self._db.execute("BEGIN")
            self._db.executemany("INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)", self._pending)
            self._db.execute("COMMIT")
            self._pending.clear()

    def size(self) -> int:
        return self._bytes

    def close(self, serialized_metadata: str) -> None:
        try:
            self.flush()
            self._db.execute("INSERT INTO metadata (metadata_version, metadata) VALUES (?, ?)",
                             (9, serialized_metadata))
            self._db.execute("PRAGMA wal_checkpoint(TRUNCATE)")
            self._db.execute("PRAGMA journal_mode=DELETE")
        finally:
            self._db.close()
