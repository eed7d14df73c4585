"""``roc launch --explain``: what a start would run, nothing started. One entry per process, for a roc.toml
system (from roc's own plan, in start-up order) and for a launch file (from the launch library, which the
launch runner lets evaluate the whole description but start nothing: roc/launch/runner.py):

    {"name", "host" (an SSH destination, or null), "setup" (files sourced there first), "command",
     "cwd", "env" (what it adds or changes), "unset", "parameters", "parameter_files", "remappings",
     and for roc.toml systems "after" and "respawn"}

rendered as text lines, or as JSON with ``--format json``."""

from __future__ import annotations

import json
import os
import shlex
from collections.abc import Callable, Mapping
from typing import Any

from roc.engine.ready import Task
from roc.launch.plan import PROCESS, start_order
from roc.launch.system import ProcessSpec, System

Entry = dict[str, Any]


def ros_arguments(command: list[str]) -> dict[str, Any]:
    """The parameters (``-p``), parameter files (``--params-file``) and remappings (``-r``) of the
    ``--ros-args`` sections of a command line, as given."""
    found: dict[str, Any] = {"parameters": {}, "parameter_files": [], "remappings": {}}
    in_ros_args = False
    words = iter(command)
    for word in words:
        if word == "--ros-args":
            in_ros_args = True
        elif word == "--":
            in_ros_args = False
        elif in_ros_args and word in ("-p", "--param", "-r", "--remap", "--params-file"):
            value = next(words, "")
            if word == "--params-file":
                found["parameter_files"].append(value)
            else:
                name, _, text = value.partition(":=")
                found["parameters" if word in ("-p", "--param") else "remappings"][name] = text
    return found


def environment_changes(base: Mapping[str, str], env: Mapping[str, str]) -> tuple[dict[str, str], list[str]]:
    """What ``env`` sets that ``base`` lacks or has otherwise, and what it drops."""
    changed = {name: value for name, value in sorted(env.items()) if base.get(name) != value}
    return changed, sorted(name for name in base if name not in env)


def system_entries(system: System, tasks: list[Task], command: Callable[[ProcessSpec], list[str]],
                   remote_env: Callable[[ProcessSpec], dict[str, str]],
                   cwd: Callable[[ProcessSpec], str]) -> list[Entry]:
    """A roc.toml system's processes in start-up order. ``command``: a process's command line (on its
    host); ``remote_env``: what roc sets for a remote process over its host's environment; ``cwd``: where
    it starts."""
    specs = {spec.label: spec for spec in system.processes}
    entries = []
    for task in start_order(tasks):
        if task.kind != PROCESS:
            continue
        spec = specs[task.name]
        line = command(spec)
        if spec.host:
            env, setup = remote_env(spec), system.hosts[spec.host].setup
        else:
            env, setup = environment_changes(os.environ, {**os.environ, **spec.env})[0], []
        entries.append({"name": spec.label, "host": spec.host or None, "setup": setup, "command": line,
                        "cwd": cwd(spec), "env": env, "unset": [], **ros_arguments(line),
                        "after": [condition.text for condition in spec.after], "respawn": spec.respawn})
    return entries


def _details(entry: Entry) -> list[str]:
    lines = []
    if entry["host"]:
        sourced = f", after sourcing {', '.join(entry['setup'])}" if entry["setup"] else ""
        lines.append(f"    on {entry['host']}{sourced}")
    lines.append(f"    {shlex.join(entry['command'])}")
    if entry["env"] or entry["unset"]:
        words = [f"{name}={shlex.quote(value)}" for name, value in entry["env"].items()]
        lines.append(f"    environment: {' '.join(words + [f'-{name}' for name in entry['unset']])}")
    return lines


def system_lines(system: System, entries: list[Entry]) -> list[str]:
    """What each process waits for, in start-up order, with the command it runs (and where, and with
    which variables, when not as roc itself)."""
    lines = [f"[launch.{system.name}] of {system.path}: {len(entries)} processes; conditions wait up to "
             f"{system.timeout:g} s"]
    for entry in entries:
        waits = entry["after"]
        lines.append(f"{entry['name']}: {'starts after: ' + ', '.join(waits) if waits else 'starts at once'}"
                     f"{' (respawns)' if entry['respawn'] else ''}")
        lines += _details(entry)
    return lines


def _flat(parameter_file: Any) -> dict[str, Any]:
    """The parameters of a parameter file (``{node: {ros__parameters: {...}}}``) by dotted name."""
    flat: dict[str, Any] = {}

    def walk(table: dict, prefix: str) -> None:
        for name, value in table.items():
            if isinstance(value, dict):
                walk(value, f"{prefix}{name}.")
            else:
                flat[f"{prefix}{name}"] = value

    for node in (parameter_file or {}).values():
        if isinstance(node, dict):
            walk(node.get("ros__parameters", {}), "")
    return flat


def file_lines(path: str, entries: list[Entry], cwd: str) -> list[str]:
    """A launch file's processes, as the launch library would start them."""
    lines = [f"{path}: {len(entries)} processes"]
    for entry in entries:
        lines.append(f"{entry['name']}:{' (respawns)' if entry.get('respawn') else ''}")
        lines += _details(entry)
        if entry["cwd"] != cwd:
            lines.append(f"    in {entry['cwd']}")
        for path in entry["parameter_files"]:
            written = entry["written_parameters"].get(path)
            if written is None:
                lines.append(f"    parameters from {path}")
            else:
                words = [f"{name}={json.dumps(value)}" for name, value in _flat(written).items()]
                lines.append(f"    parameters (in a file the launch library writes at each start): {' '.join(words)}")
        for container in entry.get("loads", []):
            lines.append(f"    loads {container['plugin']} ({container['package']}) as "
                         f"{container['namespace'].rstrip('/')}/{container['node']}")
    return lines
