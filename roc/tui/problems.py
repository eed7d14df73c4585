"""The first screen's problems line: only what is really wrong with a running system. A topic nobody
listens to is not (a sensor publishes for whoever comes; /rosout and /parameter_events have no
subscriber on a healthy system); these are: QoS or type incompatibility between endpoints, a
subscriber with no publisher, a rate below the ``min-rate`` roc.toml's ``[check]`` expects (or an
expected topic or node missing), a node that was on the graph and is gone, and a /diagnostics status in
ERROR. Plain data, no Textual.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from roc.check.expectations import CheckFile
from roc.ros.present import problem_line, topic_problems

NO_PUBLISHER = "no publisher"


@dataclass(frozen=True)
class Problem:
    kind: str  # topic or node: the list the problem's row is in; or diagnostic
    name: str
    text: str
    severity: str = "error"  # error or warning


def topic_diagnoses(topic: dict[str, Any]) -> list[str]:
    """What is wrong with a ``snapshot`` topic (with endpoints): subscribed and not published, and the
    QoS and type problems ``roc topic info -v`` reports (roc.ros.present)."""
    found = [NO_PUBLISHER] if topic["subscribers"] and not topic["publishers"] else []
    endpoints = topic.get("endpoints")
    if endpoints:
        found += [problem_line(p) for p in topic_problems(endpoints)]
    return found


def find_expectations(start: Path) -> CheckFile | None:
    """The ``[check]`` expectations of the roc.toml around ``start``, None when there is none (or it
    is not valid: ``roc graph check`` says why)."""
    from roc.check.expectations import find_check_file, load_checks
    from roc.errors import RocError

    try:
        return load_checks(find_check_file(start))
    except RocError:
        return None


class Watch:
    """The problems of each snapshot; remembers the nodes seen, to tell the ones that died."""

    def __init__(self, checks: CheckFile | None = None) -> None:
        self.checks = checks
        self.seen: dict[str, float] = {}  # node -> when it was last seen (time.time())

    def nodes_gone(self, nodes: list[str]) -> dict[str, float]:
        now = time.time()
        for node in nodes:
            self.seen[node] = now
        return {node: when for node, when in self.seen.items() if when < now}

    def forget_gone(self) -> None:
        self.seen = {node: when for node, when in self.seen.items() if when == max(self.seen.values(), default=0)}

    def problems(self, topics: list[dict[str, Any]], nodes: list[str], rate,
                 diagnostic_errors: Sequence[tuple[str, str]] = ()) -> list[Problem]:
        """``topics``, ``nodes``: what is shown; ``rate(topic)``: its measured rate or None;
        ``diagnostic_errors``: (key, text) of each /diagnostics status in ERROR."""
        found = []
        for topic in topics:
            for text in topic_diagnoses(topic):
                found.append(Problem("topic", topic["name"], f"{topic['name']}: {text}",
                                     "warning" if text == NO_PUBLISHER else "error"))
        for node, when in sorted(self.nodes_gone(nodes).items()):
            found.append(Problem("node", node, f"{node}: gone since {time.strftime('%H:%M:%S', time.localtime(when))}"))
        if self.checks is not None:
            found += self._unmet(topics, nodes, rate)
        return found + [Problem("diagnostic", key, text) for key, text in diagnostic_errors]

    def _unmet(self, topics: list[dict[str, Any]], nodes: list[str], rate) -> list[Problem]:
        assert self.checks is not None
        names = {t["name"] for t in topics}
        where = self.checks.path.name
        found = []
        for expectation in self.checks.expectations:
            if expectation.kind == "node" and expectation.name not in nodes and expectation.name not in self.seen:
                found.append(Problem("node", expectation.name, f"{expectation.name}: expected by {where}, not running"))
            if expectation.kind != "topic":
                continue
            if expectation.name not in names:
                found.append(Problem("topic", expectation.name, f"{expectation.name}: expected by {where}, "
                                                                "not on the graph"))
                continue
            least, measured = expectation.values.get("min-rate"), rate(expectation.name)
            if least is not None and measured is not None and measured < least:
                found.append(Problem("topic", expectation.name, f"{expectation.name}: {measured:.1f} Hz, below the "
                                                                f"{least:g} Hz {where} expects"))
        return found
