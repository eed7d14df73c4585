"""Interface types by name (``pkg/msg/Type``, ``pkg/Type``, ``pkg/srv/Type``, ``pkg/action/Type``).

A type is its generated Python class, imported from wherever Python finds the package: the venv's
wheels, ``/opt/ros`` or a sourced overlay. Importing a message module needs no rclpy context. When a
type cannot be found, the error says whether the package or the type is unknown, suggests close
names, and points at an unsourced ``install/`` of the current workspace that holds it.
"""

from __future__ import annotations

import importlib
import os
from functools import cache
from pathlib import Path
from typing import Any, TypeAlias

from roc.environment import ament_prefixes
from roc.errors import RocError, UsageError
from roc.messages import PACKAGE_NAME_CUTOFF, did_you_mean

KINDS = ("msg", "srv", "action")
KIND_NOUNS = {"msg": "message", "srv": "service", "action": "action"}
DEFINITION_SUFFIXES = {"msg": ".msg", "srv": ".srv", "action": ".action"}


TF_TYPE = "tf2_msgs/msg/TFMessage"  # what /tf and /tf_static carry


class UnknownTypeError(RocError):
    """An interface type that is not installed: exit 1 from every verb (as from ros2 and from
    ``roc interface show``), since the name may be right and the environment lack it."""


class TypeNameError(UsageError):
    """A type name that no installed type could have (malformed), or a type of the wrong kind for the
    verb: a usage error (exit 2) from every verb."""


# A class rosidl generated (a message, service or action, or one of their parts): dynamic, with no
# type information for a checker, so its attributes (Request, Goal, SLOT_TYPES, ...) are Any.
InterfaceClass: TypeAlias = Any

def split_type_name(name: str) -> tuple[str, str | None, str]:
    """``pkg/msg/Type`` -> ``(pkg, 'msg', Type)``; ``pkg/Type`` -> ``(pkg, None, Type)``."""
    parts = name.strip().split("/")
    if len(parts) == 3 and parts[1] in KINDS and all(parts):
        return parts[0], parts[1], parts[2]
    if len(parts) == 2 and all(parts):
        return parts[0], None, parts[1]
    raise TypeNameError(
        f"invalid type name '{name}': expected pkg/msg/Type, pkg/srv/Type, pkg/action/Type or pkg/Type")


def type_name(cls_or_instance: Any) -> str:
    """The full name of a generated class or instance, e.g. ``std_msgs/msg/String``."""
    cls = cls_or_instance if isinstance(cls_or_instance, type) else type(cls_or_instance)
    package, kind = cls.__module__.split(".")[:2]
    return f"{package}/{kind}/{cls.__name__}"


def interface_kind(cls: type) -> str:
    """``msg``, ``srv`` or ``action`` for a generated class."""
    if hasattr(cls, "Goal") and hasattr(cls, "Result") and hasattr(cls, "Feedback"):
        return "action"
    if hasattr(cls, "Request") and hasattr(cls, "Response"):
        return "srv"
    return "msg"


def _interface_module(package: str, kind: str) -> Any:
    """The generated module ``package.kind``, or None (a source directory that Python sees as a
    namespace package does not count)."""
    try:
        module = importlib.import_module(f"{package}.{kind}")
    except ImportError:
        return None
    return module if getattr(module, "__file__", None) else None


def _lookup(package: str, kind: str, name: str) -> InterfaceClass | None:
    """The class ``name`` of ``package.kind``, including the parts of services and actions that
    their modules do not export (``Fibonacci_Goal``, ``Fibonacci_FeedbackMessage``)."""
    module = _interface_module(package, kind)
    if module is None:
        return None
    found = getattr(module, name, None)
    if found is None and "_" in name:
        base = getattr(module, name.split("_", 1)[0], None)
        if isinstance(base, type):
            found = getattr(importlib.import_module(base.__module__), name, None)
    return found if isinstance(found, type) else None


@cache
def _resolve(name: str, kind: str | None) -> InterfaceClass:
    package, given_kind, short = split_type_name(name)
    kinds = [given_kind] if given_kind else [kind] if kind else list(KINDS)
    for candidate in kinds:
        found = _lookup(package, candidate, short)
        if found is not None:
            if kind and interface_kind(found) != kind:
                raise TypeNameError(
                    f"{type_name(found)} is a {KIND_NOUNS[interface_kind(found)]}, not a {KIND_NOUNS[kind]}")
            return found
    raise UnknownTypeError(_unknown_message(name, package, kinds, short))


def resolve_type(name: str, kind: str | None = None) -> InterfaceClass:
    """The class of an interface type; ``kind`` (msg, srv, action) also requires that kind and is
    the default for ``pkg/Type``. Raises UnknownTypeError with a hint, or TypeNameError."""
    return _resolve(name, kind)


def message_class(name: str) -> InterfaceClass:
    return resolve_type(name, "msg")


def service_class(name: str) -> InterfaceClass:
    return resolve_type(name, "srv")


def action_class(name: str) -> InterfaceClass:
    return resolve_type(name, "action")


# ---- errors -----------------------------------------------------------------------------------

def interface_packages() -> set[str]:
    """Interface packages in the ament index of the prefixes roc looks in (for did-you-mean hints)."""
    names: set[str] = set()
    for prefix in ament_prefixes():
        index = prefix / "share" / "ament_index" / "resource_index" / "rosidl_interfaces"
        if index.is_dir():
            names.update(entry.name for entry in index.iterdir())
    return names


def _package_types(package: str, kind: str) -> list[str]:
    module = _interface_module(package, kind)
    if module is None:
        return []
    return [n for n, v in vars(module).items() if isinstance(v, type) and "_" not in n]


def _did_you_mean(word: str, choices: list[str] | set[str], cutoff: float = 0.6) -> str:
    hint = did_you_mean(word, choices, cutoff=cutoff)
    return f" ({hint})" if hint else ""


def _unknown_message(name: str, package: str, kinds: list[str], short: str) -> str:
    nouns = " or ".join(KIND_NOUNS[k] for k in kinds)
    hint = _unsourced_hint(package, kinds, short)
    if not any(_interface_module(package, kind) for kind in KINDS):
        guess = "" if hint else _did_you_mean(package, interface_packages(), PACKAGE_NAME_CUTOFF)
        return f"unknown {nouns} type '{name}': no interface package '{package}' is installed{guess}" + (
            hint or "; install it or source the workspace that builds it")
    known = [t for k in kinds for t in _package_types(package, k)]
    guess = "" if hint else _did_you_mean(short, known)
    where = "/".join(kinds) if len(kinds) == 1 else "msg, srv or action"
    return f"unknown {nouns} type '{name}': package '{package}' has no {where} '{short}'{guess}" + (
        hint or "; see 'roc interface list'")


# System installs whose setup script may not be sourced (``/opt/ros/<distro>``).
SYSTEM_ROOTS = (Path("/opt/ros"),)


def _defines(prefix: Path, package: str, kinds: list[str], short: str) -> bool:
    share = prefix / "share" / package
    return any((share / kind / f"{short}{suffix}").is_file()
               for kind in kinds for suffix in (DEFINITION_SUFFIXES[kind], ".idl"))


def _unsourced_hint(package: str, kinds: list[str], short: str) -> str:
    """``; it is built in install, which is not sourced: ...`` when the current workspace's install
    base (isolated or merged), or a ``/opt/ros/<distro>``, holds the type's definition but is not on
    AMENT_PREFIX_PATH."""
    from roc.workspace.root import find_workspace_root

    sourced = {p.resolve() for p in ament_prefixes() if p.exists()}
    root = find_workspace_root(Path.cwd())
    install = root / "install" if root else None
    if install and install.is_dir():
        for prefix in (install / package, install):
            if prefix.resolve() not in sourced and _defines(prefix, package, kinds, short):
                shown = os.path.relpath(install)
                return f"; it is built in {shown}, which is not sourced: source {shown}/setup.bash first"
    for system in SYSTEM_ROOTS:
        for prefix in sorted(system.glob("*")) if system.is_dir() else []:
            if prefix.resolve() not in sourced and _defines(prefix, package, kinds, short):
                return f"; it is in {prefix}, which is not sourced: source {prefix}/setup.bash first"
    return ""
