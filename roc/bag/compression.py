"""rosbag2's compression: ``file`` mode (each closed storage file zstd-compressed into
``NAME.zstd``) and ``message`` mode (each message's data a zstd frame), zstd being the one format."""

from __future__ import annotations

import os
from pathlib import Path

import zstandard

from roc.bag.metadata import BagError

FORMATS = ("zstd",)
MODES = ("none", "file", "message")
SUFFIX = ".zstd"


def compress_file(path: Path) -> Path:
    """``path`` compressed into ``path.zstd`` (written whole, then ``path`` removed)."""
    target = path.with_name(path.name + SUFFIX)
    temporary = target.with_name(f".{target.name}.tmp")
    with open(path, "rb") as source, open(temporary, "wb") as sink:
        zstandard.ZstdCompressor().copy_stream(source, sink)
        sink.flush()
        os.fsync(sink.fileno())
    os.replace(temporary, target)
    path.unlink()
    return target


def decompress_file(path: Path, target: Path) -> Path:
    """``path`` (a ``.zstd`` file) decompressed to ``target``."""
    try:
        with open(path, "rb") as source, open(target, "wb") as sink:
            zstandard.ZstdDecompressor().copy_stream(source, sink)
    except OSError as error:
        raise BagError(f"{path}: cannot read it ({error.strerror})") from None
    except zstandard.ZstdError as error:
        raise BagError(f"{path}: not a whole zstd file ({error})") from None
    return target


class MessageCompressor:
    def __init__(self) -> None:
        self._compressor = zstandard.ZstdCompressor()

    def __call__(self, data: bytes) -> bytes:
        return self._compressor.compress(data)


class MessageDecompressor:
    def __init__(self, source: str) -> None:
        self._decompressor = zstandard.ZstdDecompressor()
        self._source = source

    def __call__(self, data: bytes) -> bytes:
        try:
            return self._decompressor.decompress(data)
        except zstandard.ZstdError as error:
            raise BagError(f"{self._source}: a message is not a zstd frame ({error})") from None
