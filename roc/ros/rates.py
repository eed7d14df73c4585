"""Rates, bandwidth and delays of a topic over a sliding window, from what roc.ros.dataplane's
``stats`` stream reports per message (no rclpy here).

The rate is the publisher's: publication sequence numbers over source timestamps, so messages the
subscriber lost or received late do not change it (with ``wall_time``, reception timestamps).
"""

from __future__ import annotations

import itertools
import statistics
from collections import deque
from dataclasses import dataclass

NS = 1e-9


@dataclass
class Sample:
    sequence: int | None
    source: int | None  # ns
    received: int  # ns
    size: int
    stamp: int | None  # ns, the message's header stamp


def samples(columns: dict[str, list]) -> list[Sample]:
    """The samples of one topic's ``batch`` columns."""
    return [Sample(*row) for row in zip(columns["sequence"], columns["source"], columns["received"],
                                        columns["size"], columns["stamp"])]


class Window:
    """The last ``size`` samples of a topic and the messages lost among them."""

    def __init__(self, size: int):
        self.samples: deque[Sample] = deque(maxlen=size)
        self.lost = 0
        self.unsequenced = False  # a message came without a sequence number (Cyclone DDS): loss unknown

    def add(self, new: list[Sample]) -> None:
        for sample in new:
            self.unsequenced |= sample.sequence is None
            last = self.samples[-1] if self.samples else None
            if (last and last.sequence is not None and sample.sequence is not None
                    and sample.sequence > last.sequence + 1):
                self.lost += sample.sequence - last.sequence - 1
            self.samples.append(sample)

    def known_lost(self) -> int | None:
        """The messages lost among the samples, None (unknown) when some came without a sequence number."""
        return None if self.unsequenced else self.lost

    def rate(self, wall_time: bool = False) -> dict | None:
        """``{rate, min, max, std_dev, window}`` (seconds between messages), or None before two samples."""
        rate = self.frequency(wall_time)
        if rate is None:
            return None
        times = self._times(wall_time)
        deltas = [(b - a) * NS for a, b in itertools.pairwise(times)]
        return {"rate": rate, "min": min(deltas), "max": max(deltas), "std_dev": statistics.pstdev(deltas),
                "window": len(times)}

    def frequency(self, wall_time: bool = False) -> float | None:
        """Messages per second (the ``rate`` of ``rate()`` alone, without its statistics), or None
        before two samples. Sequence numbers or source timestamps that do not rise in arrival order
        come from several publishers: the messages are then counted, and their times sorted, since
        one publisher's message can arrive after another's newer one (a transient local topic's
        history comes after live messages)."""
        times = self._times(wall_time)
        if len(times) < 2 or times[-1] == times[0]:
            return None
        first, last = self.samples[0].sequence, self.samples[-1].sequence
        one_publisher = all(a.sequence is not None and b.sequence is not None and a.sequence < b.sequence
                            and (a.source or 0) <= (b.source or 0) for a, b in itertools.pairwise(self.samples))
        messages = last - first if one_publisher and first is not None and last is not None else len(times) - 1
        return messages / ((times[-1] - times[0]) * NS)

    def _times(self, wall_time: bool) -> list[int]:
        return sorted(s.received if wall_time or s.source is None else s.source for s in self.samples)

    def bandwidth(self) -> dict | None:
        """``{bytes_per_second, messages, mean, min, max}`` (sizes in bytes), or None before two samples.
        The bytes per second are those received after the first message over the time since it came:
        n messages span n - 1 intervals (1 KB messages at 1 Hz are 1 KB/s from the second on)."""
        times = [s.received for s in self.samples]
        if len(times) < 2 or times[-1] == times[0]:
            return None
        sizes = [s.size for s in self.samples]
        return {"bytes_per_second": sum(sizes[1:]) / ((times[-1] - times[0]) * NS), "messages": len(sizes),
                "mean": statistics.fmean(sizes), "min": min(sizes), "max": max(sizes)}

    def delay(self) -> dict | None:
        """``{delay, min, max, std_dev, window}``: reception time minus header stamp (seconds)."""
        delays = [(s.received - s.stamp) * NS for s in self.samples if s.stamp is not None]
        if not delays:
            return None
        return {"delay": statistics.fmean(delays), "min": min(delays), "max": max(delays),
                "std_dev": statistics.pstdev(delays), "window": len(delays)}


def size_text(value: float) -> str:
    """Bytes as ros2 topic bw prints them: ``282 B``, ``1.50 KB``, ``2.00 MB``."""
    if value < 1000:
        return f"{value:.0f} B"
    if value < 1_000_000:
        return f"{value / 1000:.2f} KB"
    return f"{value / 1_000_000:.2f} MB"
