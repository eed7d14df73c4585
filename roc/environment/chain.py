"""The underlays an install base's ``setup.*`` scripts chain, chosen as colcon chooses them (its
``get_chained_prefix_path``): COLCON_PREFIX_PATH, then each AMENT_PREFIX_PATH entry that has a
prefix-level ``local_setup.*`` script (a package prefix of an isolated colcon install stands for that
install), without repeats or the install base itself.

colcon leaves out, with a warning, an ament prefix that has no ``local_setup.*`` script: ROS 2 installed
from wheels into a venv, which is roc's implicit underlay when nothing is sourced. roc chains such a
prefix too, by baking its packages' own environment hooks (their ``package.dsv``) into the scripts:
sourcing the workspace then brings back every underlay the build used.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from roc.environment import AMENT_INDEX, path_list
from roc.environment.dsv import Operation, resolve_operations
from roc.fsutil import write_text_atomic

INSTALL_LAYOUT_MARKER = ".colcon_install_layout"


@dataclass(frozen=True)
class Underlay:
    prefix: str
    # empty: the prefix has local_setup scripts to source; else its packages' hooks, to apply
    operations: tuple[Operation, ...] = ()


def _has_local_setup(prefix: Path) -> bool:
    try:
        return any(name.startswith("local_setup.") for name in os.listdir(prefix))
    except OSError:
        return False


def _ament_entry(path: Path) -> Underlay | None:
    """What chaining an AMENT_PREFIX_PATH entry means, or None when nothing can be chained."""
    if _has_local_setup(path):
        return Underlay(str(path))
    marker = path.parent / INSTALL_LAYOUT_MARKER
    if marker.is_file() and marker.read_text().strip() == "isolated":
        return Underlay(str(path.parent))
    operations = prefix_operations(path)
    return Underlay(str(path), operations) if operations else None


def prefix_operations(prefix: Path) -> tuple[Operation, ...]:
    """The environment operations of every package registered in an ament prefix's index, each once,
    in the order first seen (the ``source`` of a shell script without a ``.dsv`` twin is left out).
    Reading a hundred packages' hooks costs about 25 ms, so the result is kept per prefix in roc's user
    cache until the prefix's package index changes."""
    index = prefix / AMENT_INDEX / "packages"
    try:
        stamp = index.stat().st_mtime_ns
    except OSError:
        return ()
    cache = _cache_file(prefix)
    try:
        saved = json.loads(cache.read_text())
        if saved["stamp"] == stamp:
            return tuple(Operation(kind, name, tuple(values)) for kind, name, values in saved["operations"])
    except (OSError, ValueError, KeyError, TypeError):
        pass
    found: dict[Operation, None] = {}
    for name in sorted(n for n in os.listdir(index) if not n.startswith(".")):
        for operation in resolve_operations(prefix, prefix / "share" / name / "package.dsv"):
            if operation.kind != "source":
                found.setdefault(operation, None)
    operations = tuple(found)
    with contextlib.suppress(OSError):  # no cache: computed again next time
        write_text_atomic(cache, json.dumps({"stamp": stamp, "operations": [
            [o.kind, o.name, list(o.values)] for o in operations]}))
    return operations


def _cache_file(prefix: Path) -> Path:
    root = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return root / "roc" / "prefix-hooks" / f"{hashlib.sha256(str(prefix).encode()).hexdigest()[:16]}.json"


def chained_underlays(environ: Mapping[str, str], base: Path) -> list[Underlay]:
    """The underlays to chain, highest priority first (the scripts source them in reverse order)."""
    skip = os.path.realpath(base)
    chain: list[Underlay] = []
    seen = {skip}

    def add(underlay: Underlay | None) -> None:
        if underlay is not None and os.path.realpath(underlay.prefix) not in seen:
            seen.add(os.path.realpath(underlay.prefix))
            chain.append(underlay)

    for entry in path_list(environ.get("COLCON_PREFIX_PATH")):
        if os.path.exists(entry):
            add(Underlay(entry))
    for entry in path_list(environ.get("AMENT_PREFIX_PATH")):
        if os.path.exists(entry) and os.path.realpath(entry) not in seen:
            add(_ament_entry(Path(entry)))
    return chain
