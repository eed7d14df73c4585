"""Content fingerprints: a package is up to date when nothing that shapes its build has changed.

A fingerprint covers the package's source tree (hashed file by file; a file whose size and mtime are
unchanged keeps its previous hash, so a no-op check only stats files), the files its ``idl`` task
generated outside that tree (roc.idl.task), the options that shape its build, the tools its build type
runs and the underlays, and the fingerprints of its workspace dependencies, so that a change propagates
to every package that depends on it.

The parts are kept with the fingerprint of the last successful build, so that ``changes`` can say why
a package is not up to date.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import re
import sys
from pathlib import Path

from roc.environment import path_list
from roc.fsutil import file_sha256
from roc.workspace.package import IGNORE_MARKERS

# Environment that shapes builds. Volatile variables (LD_LIBRARY_PATH, whose order changes from run
# to run with the ROS wheels, PATH beyond the tools themselves, ...) are left out on purpose.
TOOLCHAIN_VARIABLES = ("CC", "CXX", "CFLAGS", "CXXFLAGS", "CPPFLAGS", "LDFLAGS", "CMAKE_GENERATOR",
                       "CMAKE_BUILD_TYPE", "ROS_DISTRO", "ROS_VERSION", "ROS_PYTHON_VERSION")
PREFIX_VARIABLES = ("AMENT_PREFIX_PATH", "CMAKE_PREFIX_PATH", "COLCON_PREFIX_PATH")
# Files an editor, a file manager or a merge tool leaves next to sources; no build reads them.
EDITOR_DROPPINGS = re.compile(r"^(\..*\.sw[a-px]|.*~|\.#.*|#.*#|\.DS_Store|4913)$")

FileStamps = dict[str, list]  # relative path -> [size, mtime_ns, sha256, executable]


def source_stamps(directory: Path, previous: FileStamps) -> FileStamps:
    """The stamps of the package's files (hidden and ignored directories and editor droppings skipped;
    symlinks followed, each real directory once). Plain strings, not Paths: this runs for every file of
    every package on a no-op build."""
    stamps: FileStamps = {}
    seen: set[tuple[int, int]] = set()
    top = str(directory)
    for dirpath, dirnames, filenames in os.walk(top, followlinks=True):
        info = os.stat(dirpath)
        real = (info.st_dev, info.st_ino)  # cheaper than realpath, which stats every component
        if real in seen or (any(m in filenames for m in IGNORE_MARKERS) and dirpath != top):
            dirnames.clear()
            continue
        seen.add(real)
        dirnames[:] = [d for d in dirnames if not d.startswith(".") and d != "__pycache__"]
        below = dirpath[len(top) + 1:]  # os.walk joins names onto ``top``: the folder relative to it
        for name in filenames:
            if name.endswith(".pyc") or EDITOR_DROPPINGS.match(name):
                continue
            path = os.path.join(dirpath, name)
            relative = os.path.join(below, name) if below else name
            try:
                info = os.stat(path)  # a symlink counts by what it points to
            except OSError:
                stamps[relative] = [0, 0, "dangling:" + os.readlink(path) if os.path.islink(path) else "", False]
                continue
            old = previous.get(relative)
            if old and old[0] == info.st_size and old[1] == info.st_mtime_ns:
                content = old[2]
            else:
                content = file_sha256(Path(path))
            stamps[relative] = [info.st_size, info.st_mtime_ns, content, bool(info.st_mode & 0o100)]
    return stamps


def source_parts(stamps: FileStamps) -> dict[str, str]:
    """What counts of each file: its content and whether it is executable."""
    return {relative: f"{stamp[2]}:{int(stamp[3])}" for relative, stamp in sorted(stamps.items())}


# Files colcon and roc write again on every build of a package, whatever changed.
REGENERATED_INSTALL_FILES = re.compile(r"share/[^/]+/(hook/|package\.|local_setup\.)|share/colcon-core/|\.pyc$")


def _newest(prefix: str) -> int:
    """The newest change time of the installed files that only a rebuild of the package rewrites.
    (ctime, not mtime: CMake's install gives a copied file its source's mtime, to the second.)"""
    newest = 0
    for dirpath, _, filenames in os.walk(prefix):
        for name in filenames:
            path = os.path.join(dirpath, name)
            if not REGENERATED_INSTALL_FILES.search(os.path.relpath(path, prefix)):
                try:
                    newest = max(newest, os.stat(path).st_ctime_ns)
                except OSError:
                    pass
    return newest


def underlay_location(name: str, prefixes: list[str] | tuple[str, ...]) -> tuple[str, str | None] | None:
    """Where an underlay has the package: (its prefix, None) when the prefix is its own (isolated),
    (the shared prefix, its package.xml) otherwise; None when no underlay has it."""
    for prefix in prefixes:
        share = os.path.join(prefix, "share", name)
        if not os.path.isdir(share):
            continue
        if os.path.basename(os.path.normpath(prefix)) == name:
            return prefix, None
        manifest = os.path.join(share, "package.xml")
        if os.path.exists(manifest):
            return prefix, manifest
    return None


def external_stamp(name: str, prefixes: list[str]) -> str | None:
    """What an underlay's package looks like now, so that rebuilding it rebuilds its dependents here.

    In its own (isolated) prefix: the newest of its installed files (rewritten when the package is
    rebuilt; scripts regenerated by every build do not count). In a shared prefix (/opt/ros, a
    venv): its package.xml. None when no underlay has it (a system library, or not installed).
    """
    found = underlay_location(name, prefixes)
    if found is None:
        return None
    prefix, manifest = found
    if manifest is None:
        return f"{prefix}:{_newest(prefix)}"
    info = os.stat(manifest)
    return f"{prefix}:{info.st_ctime_ns}:{info.st_size}"


def underlay_prefixes(env: dict[str, str], install_base: Path) -> list[str]:
    """The prefixes packages may come from, first wins (our own install base left out)."""
    own = str(install_base)
    found: list[str] = []
    for name in ("AMENT_PREFIX_PATH", "CMAKE_PREFIX_PATH"):
        for prefix in path_list(env.get(name)):
            if not prefix.startswith(own) and prefix not in found:
                found.append(prefix)
    return found


@functools.cache
def _tool_identity(name: str, path: str | None) -> str | None:
    import shutil  # here: it costs start-up (bz2, lzma), and a Python package's build has no tools

    found = shutil.which(name, path=path)
    if not found:
        return None
    real = os.path.realpath(found)
    info = os.stat(real)
    return f"{real}:{info.st_size}:{info.st_mtime_ns}"


def build_tools(build_type: str, env: dict[str, str], cmake_args: tuple[str, ...]) -> tuple[str, ...]:
    """The programs a package's build runs: for CMake, cmake, the generator's build tool and the
    compilers (CC/CXX when set); for Python, only the interpreter (counted apart)."""
    if build_type not in ("cmake", "ament_cmake"):
        return ()
    generator = env.get("CMAKE_GENERATOR", "")
    for index, arg in enumerate(cmake_args):
        if arg == "-G" and index + 1 < len(cmake_args):
            generator = cmake_args[index + 1]
        elif arg.startswith("-G"):
            generator = arg[2:]
    build_tool = "ninja" if "ninja" in generator.lower() else "make"
    return ("cmake", build_tool, env.get("CC") or "cc", env.get("CXX") or "c++")


def toolchain_parts(env: dict[str, str], install_base: Path, tools: tuple[str, ...]) -> dict[str, object]:
    """Build variables, the given tools (as found on the build's PATH), Python and underlays (entries
    inside our own install base left out, so building with the workspace itself sourced changes
    nothing)."""
    own = str(install_base)
    parts: dict[str, object] = {f"variable {name}": env.get(name) for name in TOOLCHAIN_VARIABLES}
    for name in PREFIX_VARIABLES:
        parts[f"prefix path {name}"] = [p for p in path_list(env.get(name)) if not p.startswith(own)]
    for tool in tools:
        parts[f"tool {tool}"] = _tool_identity(tool, env.get("PATH"))
    parts["python"] = [os.path.realpath(sys.executable), sys.version]
    return parts


def combine(parts: dict) -> str:
    return hashlib.sha256(json.dumps(parts, sort_keys=True).encode()).hexdigest()


def short_names(names: list[str], limit: int = 3) -> str:
    shown = ", ".join(names[:limit])
    return shown + (f" and {len(names) - limit} more" if len(names) > limit else "")


def differing_keys(old: dict, new: dict) -> list[str]:
    """The keys whose values differ between ``old`` and ``new`` (present in one only included), sorted."""
    return sorted(k for k in old.keys() | new.keys() if old.get(k) != new.get(k))


def changes(before: dict, now: dict) -> list[str]:
    """Why ``now``'s parts differ from ``before``'s, one short reason per kind of change."""
    reasons = []
    for part, what in (("sources", "files"), ("generated", "generated files")):
        old_files, new_files = before.get(part, {}), now.get(part, {})
        for label, names in (
            (f"{what} added", [f for f in new_files if f not in old_files]),
            (f"{what} changed", [f for f in new_files if f in old_files and old_files[f] != new_files[f]]),
            (f"{what} removed", [f for f in old_files if f not in new_files]),
        ):
            if names:
                reasons.append(f"{label}: {short_names(sorted(names))}")
    for part, label in (("options", "option changed"), ("toolchain", "toolchain changed"),
                        ("dependencies", "dependency changed"), ("underlay", "underlay package changed")):
        names = differing_keys(before.get(part, {}), now.get(part, {}))
        if names:
            reasons.append(f"{label}: {short_names(names)}")
    return reasons
