"""Package environments described by colcon's ``.dsv`` files, applied in Python or rendered to shell;
PATH-like lists; and the ament prefixes roc looks packages and interfaces up in."""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping
from pathlib import Path

AMENT_INDEX = Path("share", "ament_index", "resource_index")


def path_list(value: str | None) -> list[str]:
    """The entries of a PATH-like variable's value, empty entries left out."""
    return [entry for entry in (value or "").split(os.pathsep) if entry]


def own_prefix() -> Path | None:
    """roc's own Python prefix when it holds ROS packages (ROS 2 installed from wheels into roc's venv):
    the underlay roc builds on when no ROS environment is sourced, and where the message modules roc
    imports come from whatever is sourced."""
    prefix = Path(sys.prefix)
    return prefix if (prefix / AMENT_INDEX).is_dir() else None


def ament_prefixes(environ: Mapping[str, str] | None = None) -> list[Path]:
    """Where roc looks ament packages and interfaces up, highest priority first: AMENT_PREFIX_PATH,
    then roc's own prefix (``own_prefix``) if it is not listed. roc imports message modules from its own
    Python environment in every verb, so every verb's lookups include that environment too."""
    environ = os.environ if environ is None else environ
    prefixes = [Path(p) for p in path_list(environ.get("AMENT_PREFIX_PATH"))]
    own = own_prefix()
    if own is not None and own not in prefixes:
        prefixes.append(own)
    return prefixes


def with_implicit_underlay(environ: Mapping[str, str]) -> dict[str, str]:
    """``environ``, with roc's own prefix as AMENT_PREFIX_PATH when no ROS environment is sourced and
    that prefix holds ROS packages: the implicit underlay that builds start from, and that the install
    base's setup scripts then chain (roc.environment.chain)."""
    env = dict(environ)
    prefix = own_prefix()
    if not env.get("AMENT_PREFIX_PATH") and prefix is not None:
        env["AMENT_PREFIX_PATH"] = str(prefix)
    return env
