"""A cache of discovery results, so that planning a large workspace takes milliseconds.

Stored in the user's cache directory (``$ROC_CACHE_DIR``, else ``$XDG_CACHE_HOME/roc``, else
``~/.cache/roc``), one file per workspace root and discovery options. It is valid while every
directory the crawl looked at and every file identification read has the same mtime (and size), and
the variables that conditions read have the same values; anything else means a fresh discovery.

The file is in ``marshal`` format (Python's own, for plain data): reading 1000 packages takes a
fifth of the time JSON does. It names the Python version (marshal's format may change between
versions); a file that does not load is ignored, as a damaged one.
"""

from __future__ import annotations

import marshal
import os
import sys
import zlib
from collections.abc import Callable, Mapping
from pathlib import Path

from roc import __version__, messages
from roc.fsutil import write_bytes_atomic
from roc.workspace.dependencies import DependencyCycleError, topological_order
from roc.workspace.package import IGNORE_MARKERS, Package

IDENTIFICATION_FILES = ("package.xml", "setup.py", "setup.cfg", "colcon.pkg", "CMakeLists.txt", "manifest.xml")


def cache_directory() -> Path:
    if os.environ.get("ROC_CACHE_DIR"):
        return Path(os.environ["ROC_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "roc"


def _cache_key(root: Path, base_paths, paths) -> str:
    return repr([__version__, list(sys.version_info[:2]), str(root), base_paths, paths])  # json costs an import


def _cache_path(key: str) -> Path:
    # crc32 only names the file (cheaper to import than hashlib); the full key inside is checked.
    return cache_directory() / f"discovery-{zlib.crc32(key.encode()):08x}.marshal"


def _stamp(path: str) -> list[int] | None:
    try:
        info = os.stat(path)
    except OSError:
        return None
    return [info.st_mtime_ns, info.st_size]


def _inputs(root: Path, visited: list[str], packages: list[Package]) -> dict[str, list[int] | None]:
    """Every directory and file whose change could change what discovery finds. An ignore marker
    counts by its presence alone (colcon rewrites log/COLCON_IGNORE on every run)."""
    inputs = {path: [1] if os.path.basename(path) in IGNORE_MARKERS and os.path.exists(path) else _stamp(path)
              for path in visited}
    for package in packages:
        directory = str(root / package.path)
        inputs[directory] = _stamp(directory)
        names: tuple[str, ...] = IDENTIFICATION_FILES
        if package.manifest is not None and not os.path.exists(os.path.join(directory, "colcon.pkg")):
            # a ROS package is read from its package.xml alone (a build file added or removed shows in
            # the directory's mtime)
            names = ("package.xml",)
        for name in names:
            path = os.path.join(directory, name)
            if os.path.exists(path):
                inputs[path] = _stamp(path)
        if package.type == "cmake":  # dependencies come from every CMake file below it
            for dirpath, dirnames, filenames in os.walk(directory):
                dirnames[:] = [d for d in dirnames if not d.startswith(".")]
                inputs[dirpath] = _stamp(dirpath)
                for name in filenames:
                    if name == "CMakeLists.txt" or name.endswith(".cmake"):
                        inputs[os.path.join(dirpath, name)] = _stamp(os.path.join(dirpath, name))
    return inputs


def _relative(root: Path, inputs: dict[str, list[int] | None]) -> dict[str, list[int] | None]:
    """The inputs' paths relative to ``root`` where they are below it: checked from ``root``'s file
    descriptor, the kernel resolves a few path components per stat instead of every one."""
    prefix = str(root).rstrip(os.sep) + os.sep
    return {path[len(prefix):] if path.startswith(prefix) else path: stamp for path, stamp in inputs.items()}


def _all_unchanged(root: Path, inputs: dict[str, list[int] | None]) -> bool:
    """As ``_stamp(path) == stamp`` for each input (an ignore marker, ``[1]``, need only be there):
    this is most of the time of a command on a large workspace, so it stats as little as it can."""
    stat = os.stat
    directory = os.open(root, os.O_RDONLY | os.O_DIRECTORY)
    try:
        for path, stamp in inputs.items():
            try:
                info = stat(path, dir_fd=directory)  # an absolute path ignores dir_fd
            except OSError:
                if stamp is None:
                    continue
                return False
            if stamp is None or (stamp != [1] and (info.st_mtime_ns != stamp[0] or info.st_size != stamp[1])):
                return False
        return True
    finally:
        os.close(directory)


def _compact(package: dict) -> dict:
    """A package's cache entry with its manifest as marshal bytes, decoded only by a command that reads it."""
    if package["manifest"] is not None:
        package["manifest"] = marshal.dumps(package["manifest"])
    return package


def _condition_variables(packages: list[Package]) -> list[str]:
    return sorted({n for p in packages if p.manifest for n in p.manifest.condition_variables})


def cached_discovery(
    root: Path, variables: Mapping[str, str], base_paths, paths,
    discover: Callable[[list[str]], list[Package]],
) -> tuple[list[Package], bool]:
    """The packages ``discover(visited)`` finds, from the cache when nothing they came from changed, and
    whether they are in topological order: the cache keeps them so unless they form a cycle (ordering
    1000 packages took a tenth of a cached ``roc work list -t``)."""
    key = _cache_key(root, base_paths, paths)
    path = _cache_path(key)
    try:
        data = marshal.loads(path.read_bytes())
        if data["key"] == key and _all_unchanged(root, data["inputs"]):
            if all(variables.get(name) == value for name, value in data["conditions"].items()):
                packages = [Package.from_dict(item) for item in data["packages"]]
                for warning in data["warnings"]:
                    messages.warn(warning)
                return packages, data["ordered"]
    except (OSError, ValueError, EOFError, KeyError, TypeError):
        pass  # no cache yet, or one from another roc version: discover
    first_warning = len(messages.emitted)
    visited: list[str] = []
    packages = discover(visited)
    try:
        packages, ordered = topological_order(packages), True
    except DependencyCycleError:
        ordered = False
    data = {
        "key": key,
        "inputs": _relative(root, _inputs(root, visited, packages)),
        "conditions": {name: variables.get(name) for name in _condition_variables(packages)},
        "warnings": messages.emitted[first_warning:],
        "packages": [_compact(p.to_dict()) for p in packages],
        "ordered": ordered,
    }
    try:
        write_bytes_atomic(path, marshal.dumps(data))
    except OSError:
        pass  # a read-only home: work without the cache
    return packages, ordered
