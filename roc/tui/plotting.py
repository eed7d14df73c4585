"""What a plot shows, as plain data: the samples of each series (a numeric field of a topic) against
time, the window's points thinned to what the screen can draw, and the samples written as CSV; a
numeric array of a message against its index, and a LaserScan's returns as points around the sensor.
No Textual here."""

from __future__ import annotations

import bisect
import csv
import io
import math
from dataclasses import dataclass, field
from typing import Any

KEPT = 600_000  # samples kept per series (10 minutes at 1 kHz)


@dataclass
class Series:
    topic: str
    path: str  # the field, ``pose.position.x``
    times: list[float] = field(default_factory=list)  # seconds, as published
    values: list[float] = field(default_factory=list)

    @property
    def label(self) -> str:
        return f"{self.topic} {self.path}"

    def add(self, times: list[float], values: list[float | None]) -> None:
        for when, value in zip(times, values):
            if value is not None:
                self.times.append(when)
                self.values.append(value)
        if len(self.times) > KEPT:
            del self.times[:len(self.times) - KEPT // 2]
            del self.values[:len(self.values) - KEPT // 2]

    def window(self, start: float, end: float) -> tuple[list[float], list[float]]:
        first, last = bisect.bisect_left(self.times, start), bisect.bisect_right(self.times, end)
        return self.times[first:last], self.values[first:last]


def thinned(times: list[float], values: list[float], buckets: int) -> tuple[list[float], list[float]]:
    """At most two points (the lowest and the highest, in time order) per of ``buckets`` equal spans of
    time: a spike stays visible, and the plot draws a few hundred points however fast the topic."""
    if len(times) <= 2 * buckets or buckets < 1:
        return times, values
    start, span = times[0], (times[-1] - times[0]) or 1.0
    out_t: list[float] = []
    out_v: list[float] = []
    index, count = 0, len(times)
    for bucket in range(buckets):
        end = start + span * (bucket + 1) / buckets
        first = index
        while index < count and (times[index] <= end or bucket == buckets - 1):
            index += 1
        if index == first:
            continue
        chunk = range(first, index)
        low = min(chunk, key=values.__getitem__)
        high = max(chunk, key=values.__getitem__)
        for point in sorted({low, high}):
            out_t.append(times[point])
            out_v.append(values[point])
    return out_t, out_v


def numeric_paths(value: Any, prefix: str = "") -> list[str]:
    """The dotted paths of the numbers in a decoded message (arrays by index, at most 8 of each)."""
    if isinstance(value, bool) or isinstance(value, (int, float)):
        return [prefix] if prefix else []
    if isinstance(value, dict):
        return [path for key, item in value.items()
                for path in numeric_paths(item, f"{prefix}.{key}" if prefix else key)]
    if isinstance(value, list):
        return [path for index, item in enumerate(value[:8]) for path in numeric_paths(item, f"{prefix}[{index}]")]
    return []


def csv_text(series: list[Series], start: float = float("-inf"), end: float = float("inf")) -> str:
    """The samples of ``series`` between ``start`` and ``end`` as CSV: a ``time`` column (seconds, as
    published) and one per series; samples of one topic share a row."""
    rows: dict[float, dict[str, float]] = {}
    for one in series:
        for when, value in zip(*one.window(start, end)):
            rows.setdefault(when, {})[one.label] = value
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["time", *(one.label for one in series)])
    for when in sorted(rows):
        writer.writerow([f"{when:.9f}", *(repr(rows[when][one.label]) if one.label in rows[when] else ""
                                          for one in series)])
    return out.getvalue()


def array_at(message: Any, path: str) -> list[float] | None:
    """The numbers of the array at dotted ``path`` of a decoded message (``ranges``,
    ``position``), None when that is no array of numbers."""
    value = message
    for name in path.split("."):
        if not isinstance(value, dict) or name not in value:
            return None
        value = value[name]
    if not isinstance(value, list) or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in value):
        return None
    return [float(x) for x in value]


def finite_points(values: list[float]) -> tuple[list[int], list[float]]:
    """(index, value) of the finite numbers of ``values`` (a LaserScan's ``inf``: no return)."""
    kept = [(index, value) for index, value in enumerate(values) if math.isfinite(value)]
    return [index for index, _ in kept], [value for _, value in kept]


def scan_points(scan: dict[str, Any]) -> tuple[list[float], list[float]]:
    """A decoded sensor_msgs/LaserScan's returns between its ``range_min`` and ``range_max`` as x
    (forward) and y (left) in metres, in the scan's frame."""
    xs: list[float] = []
    ys: list[float] = []
    for index, distance in enumerate(scan["ranges"]):
        if scan["range_min"] <= distance <= scan["range_max"]:  # never a NaN
            angle = scan["angle_min"] + index * scan["angle_increment"]
            xs.append(distance * math.cos(angle))
            ys.append(distance * math.sin(angle))
    return xs, ys


def square_limits(reach: float, columns: int, rows: int) -> tuple[float, float]:
    """The half widths (x, y) of a plot ``columns`` x ``rows`` cells that shows ``reach`` metres around
    the origin with a metre as long across as up (braille: 2 dots a cell across, 4 up)."""
    across, up = 2 * max(1, columns), 4 * max(1, rows)
    return (reach * across / up, reach) if across >= up else (reach, reach * up / across)
