"""The command palette (``:``): every view by name (``nodes``, ``topics``, ``logs [NODE]``, ``plot TOPIC
FIELD...``, ``image TOPIC``, ``array TOPIC FIELD``, ``scan TOPIC``, ``grid TOPIC``, ``diagnostics``,
``frames``, ``bag PATH``, ``launch``, ``build``, ``publish TOPIC``), and
any node, topic, service or action of the graph by its name (every word typed must be part of it)."""

from __future__ import annotations

from collections.abc import Callable
from functools import partial

from textual.command import DiscoveryHit, Hit, Hits, Provider

from roc.tui.model import matches

# view -> (what its words after the name are, what it shows); the app's ``open`` takes the same names
VIEWS = {
    "nodes": ("", "the nodes (and topics) of the graph"),
    "topics": ("", "the topics (and nodes) of the graph"),
    "services": ("", "the services of the graph"),
    "actions": ("", "the actions of the graph"),
    "logs": ("[NODE]", "/rosout live, filtered by level, node and text"),
    "plot": ("TOPIC FIELD [FIELD...]", "numeric fields against time"),
    "image": ("TOPIC", "an image topic drawn in the terminal (sensor_msgs Image, CompressedImage)"),
    "array": ("TOPIC FIELD", "a numeric array of the newest message against its index (LaserScan ranges)"),
    "scan": ("TOPIC", "a LaserScan's returns around the sensor"),
    "grid": ("TOPIC", "an occupancy grid (nav_msgs OccupancyGrid), north up"),
    "diagnostics": ("", "/diagnostics by hardware id and name, worst first"),
    "frames": ("", "the live tf tree"),
    "publish": ("TOPIC", "publish a message on a topic, once or at a rate"),
    "bag": ("PATH", "a bag's topics and messages; play it on the graph"),
    "launch": ("", "the roc launch runs of this host: processes, output, restart, stop"),
    "build": ("", "roc work build of the workspace, shown live"),
}
NEEDS_WORDS = {"plot", "image", "array", "scan", "grid", "publish", "bag"}
FIRST = 1e9  # the score of a view named with its words: above any of Textual's fuzzy matcher (up to tens)


def palette_lines() -> list[str]:
    """One line per palette command, for the help and the manual."""
    return [f":{name}{' ' + words if words else ''}  {what}" for name, (words, what) in VIEWS.items()]


class RocCommands(Provider):
    def commands(self) -> list[tuple[str, Callable[[], object], str]]:
        app = self.app
        found: list[tuple[str, Callable[[], object], str]] = [
            (name, partial(app.open, name, ""), what)  # type: ignore[attr-defined]
            for name, (words, what) in VIEWS.items() if name not in NEEDS_WORDS]
        snapshot = app.graph_screen.snapshot if getattr(app, "graph_screen", None) else None  # type: ignore[attr-defined]
        for kind, noun in (("nodes", "node"), ("topics", "topic"), ("services", "service"), ("actions", "action")):
            for entry in (snapshot or {}).get(kind, []):
                name = entry.get("full_name", entry["name"])
                found.append((f"{noun} {name}", partial(app.open, noun, name), f"open the {noun}"))  # type: ignore[attr-defined]
        return found

    async def discover(self) -> Hits:
        for name, (words, what) in VIEWS.items():
            yield DiscoveryHit(f"{name} {words}".strip(), partial(self.app.open, name, ""),  # type: ignore[attr-defined]
                               help=what)

    async def search(self, query: str) -> Hits:
        name, _, words = query.strip().lstrip(":").partition(" ")
        view = ""
        if name in VIEWS and (words.strip() or name not in NEEDS_WORDS):  # a view with its words: first
            view = f"{name} {words}".strip()
            yield Hit(FIRST, view, partial(self.app.open, name, words.strip()),  # type: ignore[attr-defined]
                      help=VIEWS[name][1])
        matcher = self.matcher(query)
        for text, command, help_text in self.commands():
            # each word typed must appear in the entry, as the lists' filter asks (roc.tui.model.matches): the
            # fuzzy matcher alone took any entry holding the letters in order (``logs``: get_logger_levels)
            score = matcher.match(text) if text != view and matches(query.lstrip(":"), text) else 0
            if score > 0:
                yield Hit(score, matcher.highlight(text), command, help=help_text)
