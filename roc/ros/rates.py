"""Rates, bandwidth and delays of a topic over a sliding window, from what roc.ros.dataplane's
``stats`` stream reports per message (no rclpy here).

The rate is the publishers': each publisher's publication sequence numbers over its source
timestamps, so messages the subscriber lost or received late do not change it (with ``wall_time``,
reception timestamps), summed over the topic's publishers. A topic's messages alone, counted over the
time they span, read wrong while several publishers start, stop or send a late transient local
history: two 2 Hz publishers 0.1 s apart read 5 or 3.3 Hz in their first second.
"""

from __future__ import annotations

import itertools
import statistics
from collections import deque
from collections.abc import Callable, Hashable
from dataclasses import dataclass

NS = 1e-9
# A publisher silent for longer than this many of its longest intervals between messages, and at least
# STOPPED_SECONDS, by reception times against the topic's newest message, has stopped: its rate no
# longer counts, though its messages stay in the window until newer ones push them out.
STOPPED_INTERVALS = 3
STOPPED_SECONDS = 1.0
# A publisher counts from its second message. In a window's first PENDING_SECONDS, while a publisher
# was heard once only, the topic's rate is unknown rather than low (a measure that starts hears each
# publisher once before it hears any twice); later, a publisher that appears adds its rate from its
# second message on, as it adds messages.
PENDING_SECONDS = 2.0
MAX_PUBLISHERS = 256  # publishers a window remembers (their last two messages, for losses and slow rates)


@dataclass
class Sample:
    sequence: int | None
    source: int | None  # ns
    received: int  # ns
    size: int
    stamp: int | None  # ns, the message's header stamp
    publisher: Hashable = None  # the publisher's key within one stream (None: not told, all one publisher)


def samples(columns: dict[str, list]) -> list[Sample]:
    """The samples of one topic's ``batch`` columns (``publisher`` optional)."""
    return [Sample(*row) for row in zip(columns["sequence"], columns["source"], columns["received"],
                                        columns["size"], columns["stamp"],
                                        columns.get("publisher") or itertools.repeat(None))]


@dataclass
class _Heard:
    """What a Window remembers of one publisher, beyond the samples it holds."""

    last: Sample
    previous: Sample | None = None
    sequence: int | None = None  # its highest sequence number so far


class Window:
    """The last ``size`` samples of a topic and the messages lost among them (per publisher: its
    sequence numbers' gaps)."""

    def __init__(self, size: int):
        self.samples: deque[Sample] = deque(maxlen=size)
        self.lost = 0
        self.unsequenced = False  # a message came without a sequence number (Cyclone DDS): loss unknown
        self.publishers: dict[Hashable, _Heard] = {}
        self.first: int | None = None  # the reception time of the first sample (ns)
        self.newest = 0  # the latest reception time (ns)

    def add(self, new: list[Sample]) -> None:
        for sample in new:
            self.unsequenced |= sample.sequence is None
            heard = self.publishers.get(sample.publisher)
            if heard is None:
                heard = self.publishers[sample.publisher] = _Heard(sample)
                if len(self.publishers) > MAX_PUBLISHERS:
                    del self.publishers[min(self.publishers, key=lambda key: self.publishers[key].last.received)]
            else:
                heard.previous, heard.last = heard.last, sample
            if sample.sequence is not None:
                if heard.sequence is not None and sample.sequence > heard.sequence + 1:
                    self.lost += sample.sequence - heard.sequence - 1
                heard.sequence = sample.sequence if heard.sequence is None else max(heard.sequence, sample.sequence)
            if self.first is None:
                self.first = sample.received
            self.newest = max(self.newest, sample.received)
            self.samples.append(sample)

    def known_lost(self) -> int | None:
        """The messages lost among the samples, None (unknown) when some came without a sequence number."""
        return None if self.unsequenced else self.lost

    def rate(self, wall_time: bool = False) -> dict | None:
        """``{rate, min, max, std_dev, window}``, or None while ``frequency`` is: the rate is the
        publishers' (``frequency``); min, max and std_dev are those of the intervals between the topic's
        consecutive messages (seconds), as ros2 topic hz gives them, over the ``window`` messages held."""
        rate = self.frequency(wall_time)
        times = self._times(wall_time)
        if rate is None or len(times) < 2:
            return None
        deltas = [(b - a) * NS for a, b in itertools.pairwise(times)]
        return {"rate": rate, "min": min(deltas), "max": max(deltas), "std_dev": statistics.pstdev(deltas),
                "window": len(times)}

    def frequency(self, wall_time: bool = False) -> float | None:
        """Messages per second (the ``rate`` of ``rate()`` alone, without its statistics): the sum of
        each publisher's rate (``_summed``), None before one can be measured. A publisher's rate is
        its sequence numbers over its timestamps; without sequence numbers (Cyclone DDS, a filtered
        topic), or numbers or source timestamps that do not rise in arrival order (samples told no
        publisher, from several), its messages are counted over the time they span, sorted."""
        return self._summed(lambda own: _frequency(own, wall_time))

    def _summed(self, measure: Callable[[list[Sample]], float | None]) -> float | None:
        """The sum of ``measure`` over the publishers that count, each measured on its samples in the
        window (its last two heard when fewer are left: a slow publisher beside fast ones); None while
        none can be, or, in the window's first PENDING_SECONDS, while one was heard once only. A
        publisher that stopped (STOPPED_INTERVALS) counts no more."""
        held: dict[Hashable, list[Sample]] = {}
        for sample in self.samples:
            held.setdefault(sample.publisher, []).append(sample)
        total: float | None = None
        once = False
        for key, heard in self.publishers.items():
            own = held.get(key, [])
            if len(own) < 2:
                own = [heard.previous, heard.last] if heard.previous is not None else [heard.last]
            if len(own) < 2:
                once = True
                continue
            longest = max(b.received - a.received for a, b in itertools.pairwise(own))
            if self.newest - heard.last.received > max(STOPPED_INTERVALS * longest, STOPPED_SECONDS / NS):
                continue
            measured = measure(own)
            if measured is not None:
                total = measured + (total or 0.0)
        young = self.first is not None and (self.newest - self.first) * NS < PENDING_SECONDS
        return None if once and young else total

    def _times(self, wall_time: bool) -> list[int]:
        return sorted(_time(s, wall_time) for s in self.samples)

    def bandwidth(self) -> dict | None:
        """``{bytes_per_second, messages, mean, min, max}`` (sizes in bytes), or None before a
        publisher's second message (as ``frequency``). Each publisher's bytes per second are those
        received after its first message over the time since it came: n messages span n - 1
        intervals (1 KB messages at 1 Hz are 1 KB/s from the second on); the topic's are their sum."""
        bytes_per_second = self._summed(_bytes_per_second)
        if bytes_per_second is None or not self.samples:
            return None
        sizes = [s.size for s in self.samples]
        return {"bytes_per_second": bytes_per_second, "messages": len(sizes),
                "mean": statistics.fmean(sizes), "min": min(sizes), "max": max(sizes)}

    def delay(self) -> dict | None:
        """``{delay, min, max, std_dev, window}``: reception time minus header stamp (seconds)."""
        delays = [(s.received - s.stamp) * NS for s in self.samples if s.stamp is not None]
        if not delays:
            return None
        return {"delay": statistics.fmean(delays), "min": min(delays), "max": max(delays),
                "std_dev": statistics.pstdev(delays), "window": len(delays)}


def _time(sample: Sample, wall_time: bool) -> int:
    return sample.received if wall_time or sample.source is None else sample.source


def _frequency(own: list[Sample], wall_time: bool) -> float | None:
    """One publisher's rate, from its samples in arrival order (see Window.frequency)."""
    times = sorted(_time(s, wall_time) for s in own)
    if times[-1] == times[0]:
        return None
    first, last = own[0].sequence, own[-1].sequence
    in_order = all(a.sequence is not None and b.sequence is not None and a.sequence < b.sequence
                   and (a.source or 0) <= (b.source or 0) for a, b in itertools.pairwise(own))
    messages = last - first if in_order and first is not None and last is not None else len(own) - 1
    return messages / ((times[-1] - times[0]) * NS)


def _bytes_per_second(own: list[Sample]) -> float | None:
    """One publisher's bytes received after its first message over the time since it came."""
    span = own[-1].received - own[0].received
    return sum(s.size for s in own[1:]) / (span * NS) if span > 0 else None


def size_text(value: float) -> str:
    """Bytes as ros2 topic bw prints them: ``282 B``, ``1.50 KB``, ``2.00 MB``."""
    if value < 1000:
        return f"{value:.0f} B"
    if value < 1_000_000:
        return f"{value / 1000:.2f} KB"
    return f"{value / 1_000_000:.2f} MB"
