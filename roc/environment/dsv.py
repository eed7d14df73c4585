"""colcon's ``.dsv`` environment descriptions (one ``type;name;values`` operation per line).

roc reads them to build each package's environment in Python (no shell per package) and to bake the
operations into the generated shell scripts (no Python at source time).
"""

from __future__ import annotations

import os
from collections import namedtuple
from collections.abc import MutableMapping
from pathlib import Path

from roc.environment import path_list

PREPEND_TYPES = ("prepend-non-duplicate", "prepend-non-duplicate-if-exists")
APPEND_TYPES = ("append-non-duplicate",)
SET_TYPES = ("set", "set-if-unset")


class Operation(namedtuple("Operation", ("kind", "name", "values"), defaults=((),))):
    """One environment change of a prefix or a package's hook (a dsv line, or a script to source). A
    named tuple, not a dataclass: importing dataclasses costs every build's start-up 8 ms."""

    __slots__ = ()
    kind: str  # one of the types above, or "source" (a script without a .dsv twin, for the shell of its suffix)
    name: str  # variable name, or the script path for "source"
    values: tuple[str, ...]  # () by default; paths relative to the prefix (absolute ones stay absolute)


def read_dsv(path: Path) -> list[tuple[str, str, tuple[str, ...]]]:
    """The raw ``(type, first, rest)`` lines of a dsv file."""
    lines = []
    for line in path.read_text().splitlines():
        if not line.strip():
            continue
        kind, _, remainder = line.partition(";")
        first, _, rest = remainder.partition(";")
        lines.append((kind, first, tuple(rest.split(";")) if rest else ()))
    return lines


def resolve_operations(prefix: Path, dsv: Path) -> list[Operation]:
    """Operations of ``dsv`` with ``source`` lines followed: a sourced script with a ``.dsv`` twin
    is replaced by that file's operations, as colcon's setup scripts do."""
    operations: list[Operation] = []
    seen: set[Path] = set()

    def visit(path: Path) -> None:
        if path in seen or not path.is_file():
            return
        seen.add(path)
        for kind, first, rest in read_dsv(path):
            if kind == "source":
                target = prefix / first
                twin = target.with_suffix(".dsv")
                if twin.is_file():
                    visit(twin)
                else:
                    operations.append(Operation("source", first))
            else:
                operations.append(Operation(kind, first, rest or ("",)))

    visit(dsv)
    return operations


def _absolute(prefix: Path, value: str) -> str:
    return str(prefix / value) if value else str(prefix)


def set_value(prefix: Path, value: str) -> str:
    """``set`` values are paths below the prefix when such a path exists, else literal text."""
    return str(prefix / value) if value and (prefix / value).exists() else value


def apply_operations(env: MutableMapping[str, str], prefix: Path, operations: list[Operation]) -> None:
    """Change ``env`` as sourcing the package would (shell-only ``source`` operations are skipped)."""
    for operation in operations:
        if operation.kind in PREPEND_TYPES or operation.kind in APPEND_TYPES:
            for value in operation.values:
                path = _absolute(prefix, value)
                if operation.kind == "prepend-non-duplicate-if-exists" and not os.path.exists(path):
                    continue
                entries = [e for e in path_list(env.get(operation.name)) if e != path]
                entries = [path, *entries] if operation.kind in PREPEND_TYPES else [*entries, path]
                env[operation.name] = os.pathsep.join(entries)
        elif operation.kind == "set" or (operation.kind == "set-if-unset" and not env.get(operation.name)):
            env[operation.name] = set_value(prefix, operation.values[0])
