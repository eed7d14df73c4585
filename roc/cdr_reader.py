"""A message read field by field from its CDR (XCDR1, as ROS 2's DDS middlewares send it), for the few
messages whose layout roc knows and reads without rclpy's Python classes: their modules import numpy
(60 ms) for a fixed-size array, where roc needs a few fields (roc.ros.discovery_info, roc.tui.images)."""

from __future__ import annotations

import struct

from roc.errors import RocError

ENCAPSULATION_BYTES = 4  # the representation id (its low bit: little endian) and options, before the message


class Reader:
    """Each primitive aligned to its size, counted from the end of the encapsulation header."""

    def __init__(self, data: bytes, what: str = "message") -> None:
        if len(data) < ENCAPSULATION_BYTES:
            raise RocError(f"not a CDR {what} (fewer than {ENCAPSULATION_BYTES} bytes)")
        self.data, self.offset, self.what = data, ENCAPSULATION_BYTES, what
        self.order = "<" if data[1] & 1 else ">"

    def number(self, code: str) -> int | float:
        """One primitive of struct's ``code`` (``I``: uint32, ``d``: float64, ...)."""
        size = struct.calcsize(code)
        self.offset += -(self.offset - ENCAPSULATION_BYTES) % size
        try:
            (value,) = struct.unpack_from(self.order + code, self.data, self.offset)
        except struct.error:
            raise RocError(f"the {self.what} ends early") from None
        self.offset += size
        return value

    def octets(self, count: int) -> bytes:
        """A fixed-size array of ``count`` bytes (uint8[N], char[N])."""
        value = self.data[self.offset:self.offset + count]
        if len(value) < count:
            raise RocError(f"the {self.what} ends early")
        self.offset += count
        return value

    def raw(self) -> bytes:
        """A string's bytes or a sequence of octets: a uint32 length, then that many bytes."""
        return self.octets(int(self.number("I")))

    def text(self) -> str:
        return self.raw().rstrip(b"\0").decode(errors="replace")
