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
            inside = False  # in a frame whose end has not come yet
            decompressor = zstandard.ZstdDecompressor().decompressobj()
            for block in iter(lambda: source.read(1 << 20), b""):
                while block:
                    inside = True
                    sink.write(decompressor.decompress(block))
                    block = b""
                    if decompressor.eof:  # a frame ended; what follows is the next frame
                        block, inside = decompressor.unused_data, False
                        decompressor = zstandard.ZstdDecompressor().decompressobj()
            if inside:
                raise BagError(f"{path}: not a whole zstd file (it ends inside a frame: truncated?)")
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
        try:  # through a decompressobj: a frame need not say its content size
            return self._decompressor.decompressobj().decompress(data)
        except zstandard.ZstdError as error:
            raise BagError(f"{self._source}: a message is not a zstd frame ({error})") from None
