"""Declarative systems: ``[launch.NAME]`` of roc.toml, run by ``roc launch NAME`` with roc's own
supervisor (no launch library needed).

    [launch.nav]
    timeout = 30                    # seconds a process may wait for its conditions (default 30)

    [[launch.nav.process]]
    package = "nav2_map_server"
    executable = "map_server"
    name = "map_server"             # the node's name (__node); also the process's name in roc's output
    namespace = "/"                 # the node's namespace (__ns)
    parameters = { yaml_filename = "office.yaml", frame = { id = "map" } }   # nested tables: frame.id
    remappings = { map = "/office/map" }
    arguments = []                  # before --ros-args
    env = { RCUTILS_COLORIZED_OUTPUT = "0" }
    respawn = false
    respawn-delay = 1.0             # seconds (default 1)
    warm-start = true               # a Python node forked from a warm interpreter (roc/launch/warm_start.py)
    host = "user@robot"             # run it on another host, over SSH (roc/launch/remote.py)

    [launch.nav.hosts."user@robot"]
    setup = ["/opt/ros/jazzy/setup.bash", "/home/user/ws/install/setup.bash"]   # sourced there first

    [[launch.nav.process]]
    package = "nav2_amcl"
    executable = "amcl"
    after = ["service /map_server/load_map is available", "topic /scan publishes at >= 5 Hz"]

Conditions (``after``): ``node NAME exists``, ``service NAME is available``, ``action NAME is available``,
``topic NAME exists``, ``topic NAME publishes``, ``topic NAME publishes at >= RATE Hz``, and
``process NAME started`` (another process of the system; the short forms ``node NAME``, ``service NAME``
... mean the same). Each process is a task of roc's engine, each condition a probe task it depends on.
Errors name the file, the line and the key.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import tomllib

from roc.check.expectations import Expectation
from roc.config import ROC_TOML, ConfigError, check_table, header_lines, key_line
from roc.errors import UsageError
from roc.messages import did_you_mean

DEFAULT_TIMEOUT = 30.0
STRINGS = (str,)
NUMBER = (int, float)
PROCESS_KEYS: dict[str, tuple[tuple[type, ...], bool]] = {
    "package": (STRINGS, True), "executable": (STRINGS, True), "name": (STRINGS, False),
    "namespace": (STRINGS, False), "parameters": ((dict,), False), "remappings": ((dict,), False),
    "arguments": ((list,), False), "env": ((dict,), False), "respawn": ((bool,), False),
    "respawn-delay": (NUMBER, False), "after": ((list,), False), "warm-start": ((bool,), False),
    "host": (STRINGS, False),
}
SYSTEM_KEYS = {"timeout": NUMBER, "process": (list, dict), "hosts": (dict,)}
HOST_KEYS: dict[str, tuple[tuple[type, ...], bool]] = {"setup": ((str, list), False)}
# kind -> the words that may follow its name (the empty tail: the short form)
CONDITION_TAILS = {"node": ("", "exists"), "service": ("", "is available", "exists"),
                   "action": ("", "is available", "exists"), "topic": ("", "exists", "publishes"),
                   "process": ("", "started")}
CONDITION = re.compile(r"^(node|service|action|topic|process)\s+(\S+)\s*(.*?)\s*$")
RATE = re.compile(r"^publishes at\s*>=\s*([0-9.]+(?:[eE][-+]?[0-9]+)?)\s*hz$", re.IGNORECASE)
CONDITION_FORMS = ("'node NAME exists', 'service NAME is available', 'action NAME is available', 'topic NAME exists', "
                   "'topic NAME publishes [at >= RATE Hz]', 'process NAME started'")


@dataclass
class Condition:
    text: str  # as written
    expectation: Expectation | None  # what a probe checks; None for 'process NAME started'
    process: str = ""  # for 'process NAME started'


@dataclass
class ProcessSpec:
    label: str  # the process's name in roc's output, logs and tasks: [namespace/]name
    package: str
    executable: str
    name: str = ""
    namespace: str = ""
    parameters: dict[str, Any] = field(default_factory=dict)  # flattened: {"frame.id": "map"}
    remappings: dict[str, str] = field(default_factory=dict)
    arguments: list[str] = field(default_factory=list)
    env: dict[str, str] = field(default_factory=dict)
    respawn: bool = False
    respawn_delay: float = 1.0
    after: list[Condition] = field(default_factory=list)
    warm_start: bool = True
    host: str = ""  # an OpenSSH destination to run it on; "" runs it here
    where: str = ""  # file:line

    def ros_arguments(self) -> list[str]:
        """``--ros-args`` and what follows: node name, namespace, parameters (YAML values), remappings."""
        words: list[str] = []
        if self.name:
            words += ["-r", f"__node:={self.name}"]
        if self.namespace:
            words += ["-r", f"__ns:={self.namespace}"]
        for name, value in self.parameters.items():
            words += ["-p", f"{name}:={json.dumps(value)}"]
        for source, target in self.remappings.items():
            words += ["-r", f"{source}:={target}"]
        return ["--ros-args", *words] if words else []


@dataclass
class HostSpec:
    """``[launch.NAME.hosts."DEST"]``: what to source on host DEST before its processes start."""

    destination: str  # as ssh takes it: user@robot, an address, an alias of ~/.ssh/config
    setup: list[str] = field(default_factory=list)
    where: str = ""  # file:line


@dataclass
class System:
    name: str
    path: Path
    processes: list[ProcessSpec]
    timeout: float = DEFAULT_TIMEOUT
    hosts: dict[str, HostSpec] = field(default_factory=dict)  # every host a process names

    def remote(self) -> list[ProcessSpec]:
        return [spec for spec in self.processes if spec.host]


def find_roc_toml(start: Path) -> Path | None:
    """The workspace's roc.toml (at the workspace root, or here when outside a workspace)."""
    from roc.workspace.root import find_workspace_root

    path = (find_workspace_root(start) or start) / ROC_TOML
    return path if path.is_file() else None


def system_names(path: Path) -> list[str]:
    try:
        data = tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError):
        return []
    table = data.get("launch")
    return sorted(table) if isinstance(table, dict) else []


def load_system(path: Path, name: str) -> System:
    text = path.read_text()
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise UsageError(f"{path}: invalid TOML: {error}") from None
    launch = data.get("launch")
    systems: dict[str, Any] = launch if isinstance(launch, dict) else {}
    if name not in systems:
        hint = did_you_mean(name, systems, count=1)
        raise UsageError(f"{path} has no [launch.{name}]; {hint + ' ' if hint else ''}"
                         f"(systems: {', '.join(sorted(systems)) or 'none'})")
    table = systems[name]
    header = (header_lines(text, f"launch.{name}") or [1])[0]
    if not isinstance(table, dict):
        raise ConfigError(path, f"launch.{name}", "must be a table: [launch.NAME]", header)
    for key, value in table.items():
        line = key_line(text, header, key)
        if key not in SYSTEM_KEYS:
            hint = did_you_mean(key, SYSTEM_KEYS, count=1)
            raise ConfigError(path, key, f"unknown key of [launch.{name}]; {hint + ' ' if hint else ''}use timeout "
                              f"and [[launch.{name}.process]] tables", line)
        if not isinstance(value, SYSTEM_KEYS[key]) or isinstance(value, bool):
            expected = {"timeout": "a number", "process": "process tables",
                        "hosts": 'tables [launch.NAME.hosts."DEST"]'}
            raise ConfigError(path, key, f"expected {expected[key]}, got {value!r}", line)
    entries = table.get("process", [])
    entries = [entries] if isinstance(entries, dict) else entries
    if not entries:
        raise ConfigError(path, f"launch.{name}", f"no processes; add [[launch.{name}.process]] tables", header)
    starts = header_lines(text, f"launch.{name}.process")
    processes = [_process(path, text, entry, starts[i] if i < len(starts) else header, name)
                 for i, entry in enumerate(entries)]
    _check_names(path, processes)
    timeout = float(table.get("timeout", DEFAULT_TIMEOUT))
    hosts = _hosts(path, text, name, table.get("hosts", {}), header)
    for spec in processes:
        if spec.host and spec.host not in hosts:
            hosts[spec.host] = HostSpec(spec.host, [], spec.where)
    return System(name, path, processes, timeout, hosts)


def _hosts(path: Path, text: str, system: str, table: dict[str, Any], header: int) -> dict[str, HostSpec]:
    """``[launch.NAME.hosts."DEST"]`` tables: ``setup``, a file or a list of files."""
    hosts = {}
    for destination, entry in table.items():
        start = (header_lines(text, f"launch.{system}.hosts.{destination}")
                 or header_lines(text, f"launch.{system}.hosts") or [header])[0]
        where = f'[launch.{system}.hosts."{destination}"]'
        if not isinstance(entry, dict):
            raise ConfigError(path, destination, f"expected a table {where} with setup = [...]", start)
        check_table(path, text, start, entry, HOST_KEYS, where)
        setup = entry.get("setup", [])
        setup = [setup] if isinstance(setup, str) else setup
        if not all(isinstance(item, str) and item for item in setup):
            raise ConfigError(path, "setup", "expected a file or a list of files to source",
                              key_line(text, start, "setup"))
        hosts[destination] = HostSpec(destination, setup, f"{path}:{start}")
    return hosts


def _flatten(table: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    flat: dict[str, Any] = {}
    for key, value in table.items():
        if isinstance(value, dict):
            flat.update(_flatten(value, f"{prefix}{key}."))
        else:
            flat[f"{prefix}{key}"] = value
    return flat


def _process(path: Path, text: str, entry: Any, start: int, system: str) -> ProcessSpec:
    if not isinstance(entry, dict):
        raise ConfigError(path, f"launch.{system}.process", "write each process as a [[launch.NAME.process]] table",
                          start)
    check_table(path, text, start, entry, PROCESS_KEYS, f"[[launch.{system}.process]]")
    for key in ("remappings", "env"):
        if not all(isinstance(v, str) for v in entry.get(key, {}).values()):
            raise ConfigError(path, key, "expected a table of strings", key_line(text, start, key))
    for key in ("arguments", "after"):
        if not all(isinstance(v, str) for v in entry.get(key, [])):
            raise ConfigError(path, key, "expected a list of strings", key_line(text, start, key))
    host = entry.get("host", "")
    if "host" in entry and (not host or host.startswith("-") or any(c.isspace() for c in host)):
        raise ConfigError(path, "host", f"{host!r} is not an SSH destination (user@robot, an address, an alias of "
                          "~/.ssh/config)", key_line(text, start, "host"))
    name, namespace = entry.get("name", ""), entry.get("namespace", "")
    if namespace and not namespace.startswith("/"):
        namespace = f"/{namespace}"
    label = f"{namespace.strip('/')}/{name or entry['executable']}".lstrip("/")
    spec = ProcessSpec(label, entry["package"], entry["executable"], name, namespace,
                       _flatten(entry.get("parameters", {})), dict(entry.get("remappings", {})),
                       list(entry.get("arguments", [])), dict(entry.get("env", {})), entry.get("respawn", False),
                       float(entry.get("respawn-delay", 1.0)), warm_start=entry.get("warm-start", True),
                       host=entry.get("host", ""), where=f"{path}:{start}")
    line = key_line(text, start, "after")
    spec.after = [parse_condition(condition, path, line) for condition in entry.get("after", [])]
    return spec


def parse_condition(text: str, path: Path, line: int) -> Condition:
    match = CONDITION.match(text)
    if match:
        kind, name, tail = match.groups()
        rate = RATE.match(tail) if kind == "topic" else None
        if tail.lower() in CONDITION_TAILS[kind] or rate:
            if kind == "process":
                return Condition(text, None, process=name)
            values: dict[str, Any] = {}
            if rate:
                values["min-rate"] = float(rate.group(1))
            elif tail.lower() == "publishes":
                values["min-rate"] = 0.0  # messages arrive at all
            suffix = f" {tail}" if tail else ""
            return Condition(text, Expectation(kind, name, values, f"{path}:{line}", suffix))
    raise ConfigError(path, "after", f"cannot read the condition {text!r}; write one of {CONDITION_FORMS}", line)


def _check_names(path: Path, processes: list[ProcessSpec]) -> None:
    """Process names are unique, and 'process NAME started' names one of them."""
    labels = [p.label for p in processes]
    for process in processes:
        if labels.count(process.label) > 1:
            raise ConfigError(path, "name", f"two processes are named '{process.label}'; give one another name "
                              "or namespace", int(process.where.rsplit(":", 1)[1]))
        for condition in process.after:
            if condition.expectation is None and condition.process not in labels:
                hint = did_you_mean(condition.process, labels, count=1)
                raise ConfigError(path, "after", f"'{condition.text}': no process of the system is named "
                                  f"'{condition.process}'; {hint + ' ' if hint else ''}"
                                  f"(processes: {', '.join(labels)})",
                                  int(process.where.rsplit(":", 1)[1]))
            if condition.process == process.label:
                raise ConfigError(path, "after", f"'{condition.text}': a process cannot wait for itself",
                                  int(process.where.rsplit(":", 1)[1]))
