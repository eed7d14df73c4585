"""Rebuilding a bag's ``metadata.yaml`` from its files (``roc bag reindex``), e.g. after a recording
was killed. An MCAP file that was never closed (no summary, an unfinished last chunk) is first
rewritten whole from every record it still holds, so that any MCAP reader opens it; a sqlite3 file's
write-ahead log is folded into it."""

from __future__ import annotations

import os
import sqlite3
from pathlib import Path

from roc.bag.mcap_storage import McapFile, McapWriter
from roc.bag.message import Definition
from roc.bag.metadata import BagError, BagMetadata, write_metadata
from roc.bag.reader import Bag, check_storage, metadata_from_summaries


def _repair_mcap(path: Path) -> int:
    """Rewrite a never-closed MCAP file with what it still holds; returns its message count."""
    damaged = McapFile(path)
    try:
        summary = damaged.summary()
        temporary = path.with_name(f".{path.name}.reindex")
        temporary.unlink(missing_ok=True)
        writer = McapWriter(temporary)
        try:
            for topic in summary.topics:
                writer.add_topic(topic, summary.definitions.get(topic.type, Definition(topic.type, "unknown", "")))
            for message in damaged.messages():
                writer.write(message.topic, message.data, message.log_time, message.publish_time)
        finally:
            writer.close(summary.bag_metadata)
    finally:
        damaged.close()
    os.replace(temporary, path)
    return summary.message_count


def _fold_wal(path: Path) -> None:
    if path.with_name(path.name + "-wal").exists():
        try:
            with sqlite3.connect(path) as database:
                database.execute("PRAGMA wal_checkpoint(TRUNCATE)")
        except sqlite3.DatabaseError as error:
            raise BagError(f"{path}: damaged sqlite3 file ({error})") from None


def reindex(directory: Path, storage: str | None = None) -> tuple[BagMetadata, list[str]]:
    """Write ``directory``'s metadata.yaml from its files; returns it and the notes on files repaired."""
    check_storage(storage, "--storage")
    if not directory.is_dir():
        raise BagError(f"{directory}: not a bag directory (reindex rebuilds a directory's metadata.yaml)")
    (directory / "metadata.yaml").unlink(missing_ok=True)
    repaired = []
    with Bag(directory, storage) as bag:
        files, found_storage = list(bag.files), bag.storage
        incomplete = set(bag.incomplete_files)
    for path in files:
        if path in incomplete:
            count = _repair_mcap(path)
            repaired.append(f"{path.name} was not closed: rewritten with the {count} messages it held")
        elif found_storage == "sqlite3" and not path.name.endswith(".zstd"):
            _fold_wal(path)
    with Bag(directory, found_storage) as bag:
        metadata = metadata_from_summaries(found_storage, [(p.name, bag.file(p).summary()) for p in bag.files])
    write_metadata(directory, metadata)
    return metadata, repaired
