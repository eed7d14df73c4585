"""What ``roc graph check`` expects of a running system: the ``[check]`` table of roc.toml, or a file of
its own (``--file``, the same table).

    [check]
    timeout = 10                 # seconds a probe may take (default 10)
    rate-window = 2.0            # seconds over which rates are measured (default 2)
    nodes = ["/talker", "/motor"]

    [[check.topic]]
    name = "/chatter"
    type = "std_msgs/msg/String"
    min-rate = 9.0               # Hz
    max-rate = 11.0
    publishers = 1               # exact counts
    subscribers = 1
    reliability = "reliable"     # what every publisher offers
    durability = "volatile"
    compatible = true            # every publisher/subscriber pair can match (default true)

    [[check.service]]
    name = "/motor/enable"
    type = "std_srvs/srv/SetBool"
    request = "{data: true}"     # call it (YAML, as roc service call takes it) ...
    response = { success = true }  # ... and expect these response fields

    [[check.action]]
    name = "/fibonacci"
    type = "test_msgs/action/Fibonacci"

    [[check.parameter]]
    node = "/motor"
    name = "max_speed"
    value = 1.5

Unknown keys and wrong value types are errors naming the file, line and key.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import tomllib

from roc.config import ROC_TOML, ConfigError, array_item_lines, check_table, header_lines, key_line, type_names
from roc.errors import UsageError
from roc.messages import did_you_mean

NUMBER = (int, float)
# kind -> key -> (accepted types, required)
SCHEMA: dict[str, dict[str, tuple[tuple[type, ...], bool]]] = {
    "topic": {"name": ((str,), True), "type": ((str,), False), "min-rate": (NUMBER, False),
              "max-rate": (NUMBER, False), "publishers": ((int,), False), "subscribers": ((int,), False),
              "reliability": ((str,), False), "durability": ((str,), False), "compatible": ((bool,), False)},
    "service": {"name": ((str,), True), "type": ((str,), False), "request": ((str,), False),
                "response": ((dict,), False)},
    "action": {"name": ((str,), True), "type": ((str,), False)},
    "parameter": {"node": ((str,), True), "name": ((str,), True), "value": ((bool, int, float, str, list), True)},
}
SETTINGS = {"timeout": NUMBER, "rate-window": NUMBER, "nodes": (list,)}
POLICIES = {"reliability": ("reliable", "best_effort"), "durability": ("volatile", "transient_local")}


@dataclass
class Expectation:
    kind: str  # node, topic, service, action, parameter
    name: str
    values: dict[str, Any] = field(default_factory=dict)
    where: str = ""  # file:line, for messages
    suffix: str = ""  # " (2)" for the second expectation of the same thing

    @property
    def label(self) -> str:
        """The probe's name: ``topic /chatter``, ``parameter /motor max_speed``."""
        if self.kind == "parameter":
            return f"parameter {self.values['node']} {self.name}{self.suffix}"
        return f"{self.kind} {self.name}{self.suffix}"


@dataclass
class CheckFile:
    path: Path
    expectations: list[Expectation]
    timeout: float = 10.0
    rate_window: float = 2.0


def load_checks(path: Path) -> CheckFile:
    """The expectations of the ``[check]`` table of ``path``."""
    try:
        text = path.read_text()
    except OSError as error:
        raise UsageError(f"{path}: cannot read it ({error.strerror})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise UsageError(f"{path}: invalid TOML: {error}") from None
    table = data.get("check")
    if not isinstance(table, dict):
        raise UsageError(f"{path}: no [check] table; see 'roc graph check --help' for its keys")
    header = next((n for n, line in enumerate(text.splitlines(), 1) if line.strip() == "[check]"), 1)
    checks = CheckFile(path, [])
    for key, value in table.items():
        if key in SCHEMA:
            continue
        line = key_line(text, header, key)
        if key not in SETTINGS:
            hint = did_you_mean(key, [*SETTINGS, *SCHEMA], count=1)
            raise ConfigError(path, key, f"unknown key of [check]; {hint + ' ' if hint else ''}use "
                              f"{', '.join(SETTINGS)} or [[check.{']], [[check.'.join(SCHEMA)}]]", line)
        if not isinstance(value, SETTINGS[key]) or isinstance(value, bool):
            raise ConfigError(path, key, f"expected {type_names(SETTINGS[key])}, got {value!r}", line)
    checks.timeout = float(table.get("timeout", checks.timeout))
    checks.rate_window = float(table.get("rate-window", checks.rate_window))
    nodes_line = key_line(text, header, "nodes")
    node_lines = array_item_lines(text, nodes_line) if nodes_line != header else []
    for index, node in enumerate(table.get("nodes", [])):
        line = node_lines[index] if index < len(node_lines) else nodes_line  # each name's own line
        if not isinstance(node, str):
            raise ConfigError(path, "nodes", f"expected node names, got {node!r}", line)
        checks.expectations.append(Expectation("node", node, where=f"{path}:{line}"))
    for kind, schema in SCHEMA.items():
        entries = table.get(kind, [])
        if isinstance(entries, dict):
            entries = [entries]  # [check.topic] written once, as a table
        if not isinstance(entries, list):
            raise ConfigError(path, f"check.{kind}", f"write each as a [[check.{kind}]] table",
                              key_line(text, header, kind))
        starts = _entry_lines(text, header, kind)
        for index, entry in enumerate(entries):
            start = starts[index] if index < len(starts) else header
            checks.expectations.append(_expectation(path, text, kind, schema, entry, start))
    labels: dict[str, int] = {}
    for expectation in checks.expectations:  # probe names are task names: unique
        labels[expectation.label] = labels.get(expectation.label, 0) + 1
        if labels[expectation.label] > 1:
            expectation.suffix = f" ({labels[expectation.label]})"
    return checks


def _entry_lines(text: str, header: int, kind: str) -> list[int]:
    """The line of each entry of ``kind``: each ``[[check.topic]]`` header, or each inline table of
    ``topic = [{...}, ...]`` in [check] (as roc graph snapshot writes services and actions)."""
    inline = key_line(text, header, kind)
    return array_item_lines(text, inline) if inline != header else header_lines(text, f"check.{kind}")


def _expectation(path: Path, text: str, kind: str, schema: dict, entry: dict, start: int) -> Expectation:
    check_table(path, text, start, entry, schema, f"[[check.{kind}]]")
    for key in POLICIES.keys() & entry.keys():
        if entry[key] not in POLICIES[key]:
            raise ConfigError(path, key, f"expected {' or '.join(POLICIES[key])}, got {entry[key]!r}",
                              key_line(text, start, key))
    return Expectation(kind, entry["name"], {k: v for k, v in entry.items() if k != "name"}, f"{path}:{start}")


def find_check_file(start: Path) -> Path:
    """roc.toml with a [check] table in ``start`` or the nearest directory above it."""
    for directory in (start, *start.parents):
        candidate = directory / ROC_TOML
        if candidate.is_file() and re.search(r"^\s*\[+\s*check[\].]", candidate.read_text(), re.M):
            return candidate
    raise UsageError(f"no {ROC_TOML} with a [check] table here or above; write one, or pass --file FILE")
