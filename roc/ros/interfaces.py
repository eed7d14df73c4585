"""Interfaces (messages, services, actions) from the ament index of every prefix roc looks in
(``roc.environment.ament_prefixes``: AMENT_PREFIX_PATH and roc's own prefix), and their definitions
with nested types expanded as ``ros2 interface show`` prints them. Plain files: no rclpy, no daemon."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

from roc.ament_index import resources
from roc.errors import RocError
from roc.messages import did_you_mean
from roc.ros.types import TypeNameError

KINDS = ("msg", "srv", "action")
PRIMITIVES = {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32", "uint32",
              "int64", "uint64", "string", "wstring"}
SEPARATOR = "---"


def interface_packages() -> list[str]:
    return sorted(resources("rosidl_interfaces"))


def package_share(package: str) -> Path | None:
    """``share/<package>`` of the first prefix that registers the package, or None."""
    prefix = resources("packages").get(package)
    return prefix / "share" / package if prefix is not None else None


def package_interfaces(package: str | None = None) -> dict[str, dict[str, list[str]]]:
    """{package: {"msg": [names], "srv": [...], "action": [...]}}, hidden ones (with '_') left out."""
    registered = resources("rosidl_interfaces")
    if package is not None:
        if package not in resources("packages"):
            raise RocError(f"Unknown package '{package}'")
        registered = {package: registered[package]} if package in registered else {}
    result = {}
    for name, prefix in sorted(registered.items()):
        lines = (prefix / "share" / "ament_index" / "resource_index" / "rosidl_interfaces" / name).read_text()
        kinds: dict[str, set[str]] = {kind: set() for kind in KINDS}
        for line in lines.splitlines():
            kind, _, file_name = line.partition("/")
            stem, _, suffix = file_name.rpartition(".")
            if kind in kinds and "_" not in line and suffix in ("idl", kind):
                kinds[kind].add(stem)
        result[name] = {kind: sorted(names) for kind, names in kinds.items()}
    return result


def definition_path(type_name: str) -> Path:
    parts = type_name.split("/")
    if len(parts) != 3 or not all(parts) or ".." in parts:
        raise TypeNameError(f"Invalid name '{type_name}'. Expected three parts separated by '/'")
    prefix = resources("packages").get(parts[0])
    if prefix is None:
        raise RocError(f"Unknown package '{parts[0]}'")
    path = prefix / "share" / type_name
    for candidate in (path.with_name(f"{parts[2]}.{parts[1]}"), path.with_name(f"{parts[2]}.idl")):
        if candidate.is_file():
            return candidate
    known = package_interfaces(parts[0]).get(parts[0], {}).get(parts[1], [])
    hint = did_you_mean(parts[2], known) or f"'roc interface package {parts[0]}' lists its interfaces"
    raise RocError(f"{parts[0]} has no {parts[1]} named '{parts[2]}'; {hint}",
                   ros2_line=f"Could not find the interface '{path}.idl'")


def _comment_start(text: str) -> int:
    """Where a line's comment starts (-1 for none), a '#' inside a quoted default not counting."""
    quote = None
    for index, char in enumerate(text):
        if quote:
            quote = None if char == quote else quote
        elif char in "'\"":
            quote = char
        elif char == "#":
            return index
    return -1


_ARRAY = re.compile(r"\[[^\]]*\]$")
_UNIT = re.compile(r"(\s*\[([^,\]]+)\])")


def _comment_text(comment: str) -> str:
    """A comment's text as rosidl keeps it: a single bracketed unit ('[m/s]') is not part of it."""
    units = _UNIT.findall(comment)
    if len(units) == 1:
        comment = comment.replace(units[0][0], "")
    return comment.strip()


def nested_type(text: str, package: str) -> str | None:
    """The message type a field line refers to (pkg/msg/Name), None for primitives and constants."""
    code = text[:_comment_start(text)] if _comment_start(text) >= 0 else text
    words = code.split()
    if len(words) < 2 or "=" in code.split(words[0], 1)[1].split()[0] or "=" in words[1]:
        return None
    base = _ARRAY.sub("", words[0])
    base = base.split("<=")[0]
    if base in PRIMITIVES:
        return None
    if "/" in base:
        pkg, name = base.split("/", 1)
        return f"{pkg}/msg/{name.split('/')[-1]}"
    if base == "Header":
        return "std_msgs/msg/Header"
    return f"{package}/msg/{base}"


def installed_definition(type_name: str) -> str:
    """The text of an installed interface's definition file."""
    return definition_path(type_name).read_text()


# An interface defined in IDL only, as Kilted's keyed types are (test_msgs/msg/KeyedString: '@key string key;'):
# no .msg file to read line by line, and its nested types named by #include lines
IDL_MODULE = re.compile(r"^\s*module\s+\w+\s*\{", re.MULTILINE)


def show_lines(type_name: str, comments: bool = True, nested_comments: bool = False, level: int = 0,
               read: Callable[[str], str] = installed_definition) -> list[str]:
    """The definition of ``type_name`` (its text from ``read``) with every nested message expanded one
    tab deeper; an IDL-only definition as it is written."""
    package = type_name.split("/")[0]
    definition = read(type_name)
    if IDL_MODULE.search(definition):
        return [f"{chr(9) * level}{line.rstrip()}" if line.strip() else "" for line in definition.splitlines()]
    lines = []
    for raw in definition.splitlines():
        text = raw.rstrip()
        start = _comment_start(text)
        comment = _comment_text(text[start + 1:]) if start >= 0 else ""
        # As ros2 (rosidl's parser): a comment line starts in column 0 and has text ('#', '##' or a
        # lone unit such as '# [m]' is no comment, nor is an indented one); a trailing comment is cut one
        # character before its text, which keeps the '#' of '# text'.
        is_comment = text.startswith("#") and bool(_comment_text(text.lstrip("#")))
        shown = text
        if not comments:
            if not text or is_comment:
                continue
            if start > 0 and text[:start].strip() and comment:
                shown = text[:text.find(comment, start) - 1].strip()
        lines.append(f"{chr(9) * level}{shown}" if shown else "")
        if text != SEPARATOR and not text.lstrip().startswith("#"):
            nested = nested_type(text, package)
            if nested:
                lines += show_lines(nested, nested_comments, nested_comments, level + 1, read)
    return lines
