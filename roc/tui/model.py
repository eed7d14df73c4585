"""What ``roc tui`` shows, as plain data: the rows of each list made from the daemon's answers, the
live rates and bandwidths of topics, the nodes' processes, the filter. No Textual here (unit-testable).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any, cast

from roc.ros.present import is_hidden
from roc.ros.rates import Window, samples, size_text
from roc.tui.problems import topic_diagnoses
from roc.tui.processes import Usage, cpu_text, memory_text

# Messages kept per topic for the list's rates: enough for a steady rate, little memory for 200 topics
# (roc topic hz keeps 10000 of one topic; the topic screen does too).
LIST_WINDOW = 500
TOPIC_WINDOW = 10000
SETTLED = 2.0  # seconds a new rates stream measures before its rates replace the last stream's


@dataclass
class Row:
    """One line of a list: its key (the name) and its cells; ``problems`` makes it stand out."""

    key: str
    cells: tuple[str, ...]
    problems: list[str] = field(default_factory=list)


def matches(needle: str, *texts: str) -> bool:
    """The filter: every word of ``needle`` appears (any case) in one of ``texts``."""
    haystack = " ".join(texts).lower()
    return all(word in haystack for word in needle.lower().split())


ELLIPSIS = "…"
SHORTEST = 8  # a column is cut to no fewer cells: below that, the list scrolls sideways (Left/Right)


def shorten(text: str, width: int, type_name: bool = False) -> str:
    """``text`` in at most ``width`` characters: a type first without its ``msg/`` (``std_msgs/String``,
    which ros2 takes too), then without its middle (``/robot1/cont…_server``), so that both ends stay."""
    if len(text) <= width:
        return text
    if type_name:
        text = re.sub(r"/(msg|srv|action)/", "/", text)
        if len(text) <= width:
            return text
    head = width // 2
    return text[:head] + ELLIPSIS + text[len(text) - (width - head - 1):] if width > 1 else text[:width]


def cut_widths(room: int, widths: list[int]) -> int | None:
    """The one width to cut the widest of columns ``widths`` wide to, so that they fit ``room`` together
    (the narrower ones kept whole); None when they fit uncut."""
    if sum(widths) <= room:
        return None
    kept = 0
    for index, width in enumerate(sorted(widths)):
        left = len(widths) - index  # the columns this width and wider
        if kept + width * left > room:
            return max(SHORTEST, (room - kept) // left)
        kept += width
    return None


UNITS = {"": 1.0, "k": 1e3, "K": 1e3, "M": 1e6, "G": 1e9, "T": 1e12}


def cell_number(text: str) -> float | None:
    """A cell's number as the lists sort it (``12%``, ``45M``, ``2.0 Hz``, ``1.2 kHz``, ``1.50 KB/s``,
    a pid), None for a text (``remote``, ``gone``, ``-``)."""
    found = re.match(r"(-?\d+(?:\.\d+)?)\s*([kKMGT]?)", text)
    return float(found.group(1)) * UNITS[found.group(2)] if found else None


def sorted_rows(rows: list[Row], column: int, descending: bool) -> list[Row]:
    """``rows`` by their cells of ``column``: the numbers by value, then the texts, then the empty cells
    (a node on another host, one gone), each in the order asked for."""
    numbers = [row for row in rows if cell_number(row.cells[column]) is not None]
    texts = [row for row in rows if cell_number(row.cells[column]) is None and row.cells[column]]
    empty = [row for row in rows if not row.cells[column]]
    return (sorted(numbers, key=lambda row: cast(float, cell_number(row.cells[column])), reverse=descending)
            + sorted(texts, key=lambda row: row.cells[column].lower(), reverse=descending) + empty)


def shown_endpoints(endpoints: dict[str, Any]) -> dict[str, Any]:
    """A topic's endpoints less those of hidden nodes (ros2's rule), such as the roc daemon's own
    subscriptions that measure the rates: they would count as subscribers."""
    return {side: [e for e in endpoints[side] if not is_hidden(e["node_name"])]
            for side in ("publishers", "subscribers")}


def with_shown_endpoints(topic: dict[str, Any]) -> dict[str, Any]:
    """A ``snapshot`` topic whose counts leave hidden nodes out (when its endpoints are known)."""
    if not topic.get("endpoints"):
        return topic
    endpoints = shown_endpoints(topic["endpoints"])
    return {**topic, "endpoints": endpoints, "publishers": len(endpoints["publishers"]),
            "subscribers": len(endpoints["subscribers"])}


def rate_text(rate: float | None) -> str:
    return "-" if rate is None else f"{rate:.1f} Hz" if rate < 1000 else f"{rate / 1000:.2f} kHz"


def bandwidth_text(bytes_per_second: float | None) -> str:
    return "-" if bytes_per_second is None else f"{size_text(bytes_per_second)}/s"


class Rates:
    """The rate and bandwidth of each topic, from the ``stats`` stream's batches, as roc topic hz and
    bw measure them (roc.ros.rates): the sum of each publisher's, so that a topic with several
    publishers reads right from the second message of each (in a stream's first 2 s, nothing before
    that: roc.ros.rates.PENDING_SECONDS).

    Each stream (``restart``: the first screen asks for a new one whenever the published topics change)
    fills windows of its own: each stream numbers the publishers of its ``publisher`` column from 0, and
    a window holding the messages of two streams would span the time between them, when no message was
    received (counted messages read low: 0.7 Hz for 2.1 after some restarts under load). The last
    stream's windows are shown until the new ones have measured for SETTLED seconds."""

    def __init__(self, size: int = LIST_WINDOW):
        self.size = size
        self.windows: dict[str, Window] = {}
        self.before: dict[str, Window] = {}  # the windows of the stream before, until the new ones measure
        self.in_view: set[str] | None = None  # the topics whose texts are measured again (None: all)
        self._texts: dict[str, tuple[str, str]] = {}

    def add(self, event: dict[str, Any]) -> None:
        """Take a ``batch`` event."""
        for topic, columns in event["topics"].items():
            self.windows.setdefault(topic, Window(self.size)).add(samples(columns))

    def restart(self) -> None:
        """A new stream starts: its batches fill new windows."""
        self.before = {**self.before, **{topic: window for topic, window in self.windows.items()
                                         if window.frequency() is not None}}
        self.windows = {}

    def keep(self, topics: set[str]) -> None:
        """Forget the topics that are gone."""
        for measured in (self.windows, self.before):
            for topic in set(measured) - topics:
                del measured[topic]
        for topic in set(self._texts) - topics:
            del self._texts[topic]

    def _window(self, topic: str, measure) -> Any:
        """``measure`` of the topic's window, or of the last stream's until the new one spans SETTLED
        seconds and measures (a rate over a few messages is less steady than the last stream's)."""
        window, before = self.windows.get(topic), self.before.get(topic)
        if window and len(window.samples) > 1 and (
                before is None or (window.samples[-1].received - window.samples[0].received) * 1e-9 >= SETTLED):
            measured = measure(window)
            if measured is not None or before is None:
                return measured
        return measure(before) if before else None

    def rate(self, topic: str) -> float | None:
        return self._window(topic, Window.frequency)

    def bandwidth(self, topic: str) -> float | None:
        measured = self._window(topic, Window.bandwidth)
        return measured["bytes_per_second"] if measured else None

    def texts(self, topic: str) -> tuple[str, str]:
        """The rate and bandwidth as the list shows them: measured again for a topic in view, the last
        ones for the others (200 topics measured every second cost more than everything else drawn)."""
        if self.in_view is None or topic in self.in_view or topic not in self._texts:
            self._texts[topic] = (rate_text(self.rate(topic)), bandwidth_text(self.bandwidth(topic)))
        return self._texts[topic]


def visible(entries: list[dict[str, Any]], hidden: bool) -> list[dict[str, Any]]:
    """Entries without a hidden name (ros2's rule), unless ``hidden``; topics counted without the
    endpoints of hidden nodes."""
    shown = entries if hidden else [e for e in entries if not is_hidden(e.get("full_name", e["name"]))]
    return [with_shown_endpoints(e) if "endpoints" in e and not hidden else e for e in shown]


def topic_rows(snapshot: dict[str, Any], rates: Rates, hidden: bool = False) -> list[Row]:
    return [Row(t["name"], (t["name"], str(t["publishers"]), str(t["subscribers"]), *rates.texts(t["name"]),
                            ", ".join(t["types"])), topic_diagnoses(t))
            for t in visible(snapshot["topics"], hidden)]


def node_rows(snapshot: dict[str, Any], hidden: bool = False, usage: dict[str, Usage] | None = None,
              gone: dict[str, float] | None = None) -> list[Row]:
    """Each node with its process's CPU (% of a core; ``remote`` on another host), resident memory
    (shared by the nodes of one process) and process id; then the nodes ``gone`` (name -> when last seen)."""
    names = [n["full_name"] for n in snapshot["nodes"]]
    usage = usage or {}
    rows = [Row(n["full_name"], (n["full_name"], cpu_text(usage.get(n["full_name"])),
                                 memory_text(usage.get(n["full_name"])), pid_text(usage.get(n["full_name"]))),
                ["duplicate name"] if names.count(n["full_name"]) > 1 else [])
            for n in visible(snapshot["nodes"], hidden)]
    return rows + [Row(name, (name, "gone", "", ""), ["gone"]) for name in sorted(gone or {})]


def pid_text(usage: Usage | None) -> str:
    return str(usage.pid) if usage is not None and usage.pid is not None else ""


def typed_rows(entries: list[dict[str, Any]], hidden: bool = False) -> list[Row]:
    """Services or actions: name and type."""
    return [Row(e["name"], (e["name"], ", ".join(e["types"]))) for e in visible(entries, hidden)]


def counts(snapshot: dict[str, Any], hidden: bool = False) -> dict[str, int]:
    """How many of each kind the header shows."""
    return {kind: len(visible(snapshot[kind], hidden)) for kind in ("nodes", "topics", "services", "actions")}


def duration_text(ns: int | None) -> str:
    return "Infinite" if ns is None else f"{ns / 1e6:g} ms"  # ros2 topic info -v's word for none


def endpoint_cells(endpoint: dict[str, Any]) -> tuple[str, ...]:
    """An endpoint as a row: node, side, reliability, durability, history (depth), deadline."""
    qos = endpoint["qos"]
    history = f"KEEP_LAST ({qos['depth']})" if qos["history"] == "KEEP_LAST" else qos["history"]
    who = f"{endpoint['node_namespace'].rstrip('/')}/{endpoint['node_name']}"
    side = "publisher" if endpoint["endpoint_type"] == "PUBLISHER" else "subscriber"
    return who, side, qos["reliability"], qos["durability"], history, duration_text(qos["deadline_ns"])


# why an endpoint's history is UNKNOWN (rmw's RMW_QOS_POLICY_HISTORY_UNKNOWN, depth 0)
UNKNOWN_HISTORY = "history (depth) UNKNOWN: not carried by DDS discovery; ros2 topic info -v: same"


def endpoint_detail(endpoint: dict[str, Any]) -> str:
    """The rest of ros2 topic info -v's QoS profile of an endpoint, and why its history may be unknown."""
    qos = endpoint["qos"]
    lines = [f"lifespan {duration_text(qos['lifespan_ns'])}, liveliness {qos['liveliness']} (lease "
             f"{duration_text(qos['liveliness_lease_duration_ns'])}), GID {endpoint['gid']}"]
    if qos["history"] == "UNKNOWN":
        lines.append(UNKNOWN_HISTORY)
    return "\n".join(lines)
