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
from collections import namedtuple
from collections.abc import Mapping
from pathlib import Path

from roc.environment import AMENT_INDEX, path_list
from roc.environment.dsv import Operation, resolve_operations
from roc.fsutil import write_text_atomic

INSTALL_LAYOUT_MARKER = ".colcon_install_layout"
CACHE_VERSION = 2  # of prefix_operations' cache: 2 added wheel_library_operations
# where a linker looks without LD_LIBRARY_PATH (Debian's multiarch folders included)
SYSTEM_LIBRARY_FOLDERS = ("/lib", "/usr/lib", "/lib64", "/usr/lib64", "/usr/local/lib")


class Underlay(namedtuple("Underlay", ("prefix", "operations"), defaults=((),))):
    """A prefix of the environment chain and how its environment is made (a named tuple, as
    roc.environment.dsv.Operation)."""

    __slots__ = ()
    prefix: str
    # empty (the default): the prefix has local_setup scripts to source; else its packages' hooks, to apply
    operations: tuple[Operation, ...]


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
        if saved["stamp"] == stamp and saved.get("version") == CACHE_VERSION:
            return tuple(Operation(kind, name, tuple(values)) for kind, name, values in saved["operations"])
    except (OSError, ValueError, KeyError, TypeError):
        pass
    found: dict[Operation, None] = {}
    for name in sorted(n for n in os.listdir(index) if not n.startswith(".")):
        for operation in resolve_operations(prefix, prefix / "share" / name / "package.dsv"):
            if operation.kind != "source":
                found.setdefault(operation, None)
    for operation in wheel_library_operations(prefix):
        found.setdefault(operation, None)
    operations = tuple(found)
    with contextlib.suppress(OSError):  # no cache: computed again next time
        write_text_atomic(cache, json.dumps({"stamp": stamp, "version": CACHE_VERSION, "operations": [
            [o.kind, o.name, list(o.values)] for o in operations]}))
    return operations


def wheel_library_operations(prefix: Path) -> list[Operation]:
    """For ROS 2 installed from PyPI wheels into a Python environment: the library folders its C and C++
    libraries need at run time that no package hook names. The wheels' libraries find their bundled
    dependencies (``site-packages/ros_*.libs``: tinyxml2, spdlog, lttng-ust...) only through the
    LD_LIBRARY_PATH their bootstrapper gives Python processes, so a C++ program run from a shell that
    sourced a workspace would not start; and C++ programs linking rcl need the interpreter's shared
    libpython (see roc.doctor.wheel_repairs), whose folder a pyenv or self-built Python keeps outside
    the linker's search path."""
    folders = sorted(prefix.glob("lib/python3*/site-packages/ros_*.libs"))
    if not folders:
        return []
    operations = [Operation("prepend-non-duplicate", "LD_LIBRARY_PATH", (str(folder.relative_to(prefix)),))
                  for folder in folders]
    libpython = _libpython_folder(prefix)
    if libpython is not None:
        operations.append(Operation("prepend-non-duplicate", "LD_LIBRARY_PATH", (libpython,)))
    return operations


def _libpython_folder(prefix: Path) -> str | None:
    """The folder of the shared libpython of the venv at ``prefix``'s interpreter (``home`` in its
    pyvenv.cfg), when the linker would not look there by itself."""
    try:
        config = (prefix / "pyvenv.cfg").read_text()
    except OSError:
        return None
    home = next((line.split("=", 1)[1].strip() for line in config.splitlines()
                 if line.split("=", 1)[0].strip() == "home"), None)
    if not home:
        return None
    folder = os.path.realpath(os.path.join(home, os.pardir, "lib"))
    found = any(name.startswith("libpython3") and ".so" in name for name in _listdir(folder))
    system = any(folder == root or folder.startswith(root + "/") for root in SYSTEM_LIBRARY_FOLDERS)
    return folder if found and not system else None


def _listdir(folder: str) -> list[str]:
    try:
        return os.listdir(folder)
    except OSError:
        return []


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
