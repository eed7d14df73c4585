"""Names shared by both directions of the .proto <-> .msg converter (ROS 2 naming rules)."""

from __future__ import annotations

import re

# Marks an enum value that msg -> proto added (proto3 needs a zero value): proto -> msg skips it.
ADDED_MARK = "roc: added for proto3, not a ROS constant"
# Prefix of the comment lines that carry ROS constants protobuf cannot express (read back by proto -> msg).
CONSTANT_MARK = "ROS constant: "
# ROS package suffixes kept as they are when a proto package becomes a ROS package.
ROS_SUFFIXES = ("_msgs", "_interfaces")


def words(name: str) -> list[str]:
    """``fooBar_baz``, ``FooBAR2`` -> lower-case words."""
    spaced = re.sub(r"([a-z0-9])([A-Z])", r"\1 \2", name)
    spaced = re.sub(r"([A-Z]+)([A-Z][a-z])", r"\1 \2", spaced)
    return [w.lower() for w in re.split(r"[^A-Za-z0-9]+", spaced) if w]


MESSAGE = re.compile(r"^[A-Z][A-Za-z0-9]*$")
FIELD = re.compile(r"^[a-z](_?[a-z0-9]+)*$")
CONSTANT = re.compile(r"^[A-Z](_?[A-Z0-9]+)*$")


def camel(name: str) -> str:
    """``foo_bar`` -> ``FooBar`` (a valid ROS message name part; a valid one is kept)."""
    if MESSAGE.match(name):
        return name
    return "".join(w[:1].upper() + w[1:] for w in words(name))


def snake(name: str) -> str:
    """``fooBar`` -> ``foo_bar`` (a valid ROS field name; a valid one is kept)."""
    if FIELD.match(name):
        return name
    text = "_".join(words(name))
    return text if text[:1].isalpha() else f"f_{text}"


def constant(name: str) -> str:
    """A ROS constant name: upper case, single underscores, starting with a letter (a valid one is kept)."""
    if CONSTANT.match(name):
        return name
    text = "_".join(w.upper() for w in words(name))
    return text if text[:1].isalpha() else f"C_{text}"


def ros_package(proto_package: str) -> str:
    """``a.b`` -> ``a_b_msgs``; a name already ending in ``_msgs``/``_interfaces`` is kept."""
    name = "_".join(snake(part) for part in proto_package.split("."))
    return name if name.endswith(ROS_SUFFIXES) else f"{name}_msgs"
