"""Full type definitions from the ament index, as rosbag2 stores them with each topic: the type's
``.msg`` text, then each type it uses (depth first, each once) after a line of 80 ``=`` and
``MSG: pkg/Type``; a type with no ``.msg`` falls back to its ``.idl`` files (``ros2idl``); services
(event topics) start with ``SRV: pkg/srv/Name``. The text is the files' own, comments included, as
rosbag2's LocalMessageDefinitionSource writes it. Also the type's RIHS01 hash from rosidl's
``.json`` type description."""

from __future__ import annotations

import json
import re
from functools import cache

from roc.bag.message import Definition
from roc.ros.interfaces import package_share

DELIMITER = "=" * 80 + "\n"
_TYPE_NAME = re.compile(r"^([a-zA-Z0-9_]+)/(?:msg/|srv/)?([a-zA-Z0-9_]+)$")
_MSG_FIELD_TYPE = re.compile(r"(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+")
_IDL_INCLUDE = re.compile(r'(?:^|\n)#include\s+(?:"|<)([a-zA-Z0-9_/]+)\.idl(?:"|>)')
PRIMITIVES = {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32", "uint32",
              "int64", "uint64", "string", "wstring"}
MAX_DEPTH = 50


class _NotFound(Exception):
    pass


def _file(type_name: str, kind: str, suffix: str) -> str:
    match = _TYPE_NAME.match(type_name)
    if not match:
        raise _NotFound(type_name)
    share = package_share(match.group(1))
    path = share / kind / f"{match.group(2)}{suffix}" if share is not None else None
    try:
        return path.read_text() if path is not None else _raise(type_name)
    except OSError:
        raise _NotFound(type_name) from None


def message_sections(definition: Definition) -> dict[str, str]:
    """The ``.msg`` text of each type a ``ros2msg`` definition holds, by full name (``pkg/msg/Type``): its
    own type's first, then each ``MSG:`` section's (empty for another encoding)."""
    if definition.encoding != "ros2msg":
        return {}
    sections = {definition.type: ""}
    current = definition.type
    lines: list[str] = []
    for line in definition.text.split("\n"):
        if line == DELIMITER.rstrip("\n"):
            continue
        if line.startswith("MSG: "):
            sections[current] = "\n".join(lines).strip("\n") + "\n"
            name = line[len("MSG: "):].strip()
            package, _, short = name.rpartition("/")
            current = name if name.count("/") == 2 else f"{package}/msg/{short}"
            lines = []
            continue
        lines.append(line)
    sections[current] = "\n".join(lines).strip("\n") + "\n"
    return sections


def _raise(type_name: str) -> str:
    raise _NotFound(type_name)


def msg_dependencies(text: str, package: str) -> list[str]:
    found = set()
    for match in _MSG_FIELD_TYPE.finditer(text):
        name = match.group(1)
        if name in PRIMITIVES:
            continue
        found.add(name if "/" in name else f"{package}/{name}")
    return sorted(found)


def _idl_dependencies(text: str) -> list[str]:
    return sorted({match.group(1) for match in _IDL_INCLUDE.finditer(text)})


def _expand(name: str, idl: bool, seen: set[str], depth: int) -> str:
    if depth <= 0:
        raise _NotFound(name)
    package = name.split("/")[0]
    if idl:
        text = _file(name, "msg", ".idl")
        dependencies = _idl_dependencies(text)
    else:
        text = _file(name, "msg", ".msg")
        dependencies = msg_dependencies(text, package)
    for dependency in dependencies:
        if (dependency, idl) not in seen:
            seen.add((dependency, idl))  # type: ignore[arg-type]
            heading = f"\n{DELIMITER}{'IDL' if idl else 'MSG'}: {dependency}\n"
            text += heading + _expand(dependency, idl, seen, depth - 1)
    return text


@cache
def definition(type_name: str) -> Definition:
    """The full definition of ``type_name`` (``pkg/msg/Type`` or a service's ``pkg/srv/Name_Event``),
    with encoding ``unknown`` and no text when the index lacks it."""
    type_hash = type_hash_of(type_name)
    parts = type_name.split("/")
    if len(parts) == 3 and parts[1] == "srv":
        service = f"{parts[0]}/srv/{parts[2].removesuffix('_Event')}"
        try:
            return Definition(type_name, "ros2msg", _service_text(service), type_hash)
        except _NotFound:
            return Definition(type_name, "unknown", "", type_hash)
    try:
        return Definition(type_name, "ros2msg", _expand(type_name, False, set(), MAX_DEPTH), type_hash)
    except _NotFound:
        pass
    try:
        root = f"{DELIMITER}IDL: {type_name}\n"
        return Definition(type_name, "ros2idl", root + _expand(type_name, True, set(), MAX_DEPTH), type_hash)
    except _NotFound:
        return Definition(type_name, "unknown", "", type_hash)


def _service_text(service: str) -> str:
    text = _file(service, "srv", ".srv")
    result = f"{DELIMITER}SRV: {service}\n{text}"
    seen: set = set()
    for dependency in msg_dependencies(text, service.split("/")[0]):
        if (dependency, False) not in seen:
            seen.add((dependency, False))
            result += f"\n{DELIMITER}MSG: {dependency}\n" + _expand(dependency, False, seen, MAX_DEPTH)
    return result


def type_hash_of(type_name: str) -> str:
    """The RIHS01 hash rosidl wrote into ``share/pkg/KIND/Type.json``, '' when absent."""
    parts = type_name.split("/")
    if len(parts) != 3:
        return ""
    share = package_share(parts[0])
    name = parts[2].removesuffix("_Event") if parts[1] == "srv" else parts[2]
    path = share / parts[1] / f"{name}.json" if share is not None else None
    try:
        document = json.loads(path.read_text()) if path is not None else {}
    except (OSError, ValueError):
        return ""
    return next((h.get("hash_string", "") for h in document.get("type_hashes", [])
                 if h.get("type_name") == type_name), "")

