"""Content fingerprints: a package is up to date when nothing that shapes its build has changed.

A fingerprint covers the package's source tree (hashed file by file; a file whose size and mtime are
unchanged keeps its previous hash, so a no-op check only stats files), the options that shape its
build, the toolchain and underlays, and the fingerprints of its workspace dependencies, so that a
change propagates to every package that depends on it.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import sys
from pathlib import Path

from roc.fsutil import file_sha256
from roc.workspace.package import IGNORE_MARKERS

# Environment that shapes builds. Volatile variables (LD_LIBRARY_PATH, whose order changes from run
# to run with the ROS wheels, PATH beyond the tools themselves, ...) are left out on purpose.
TOOLCHAIN_VARIABLES = ("CC", "CXX", "CFLAGS", "CXXFLAGS", "CPPFLAGS", "LDFLAGS", "CMAKE_GENERATOR",
                       "CMAKE_BUILD_TYPE", "ROS_DISTRO", "ROS_VERSION", "ROS_PYTHON_VERSION")
PREFIX_VARIABLES = ("AMENT_PREFIX_PATH", "CMAKE_PREFIX_PATH", "COLCON_PREFIX_PATH")
TOOLS = ("cmake", "make", "ninja", "cc", "c++", "gcc", "g++")

FileStamps = dict[str, list]  # relative path -> [size, mtime_ns, sha256]


def source_digest(directory: Path, previous: FileStamps) -> tuple[str, FileStamps]:
    """Digest of the package's files (hidden and ignored directories skipped) and the new stamps."""
    stamps: FileStamps = {}
    for dirpath, dirnames, filenames in os.walk(directory):
        if any(marker in filenames for marker in IGNORE_MARKERS) and dirpath != str(directory):
            dirnames.clear()
            continue
        dirnames[:] = [d for d in dirnames if not d.startswith(".") and d != "__pycache__"]
        for name in filenames:
            if name.endswith(".pyc"):
                continue
            path = Path(dirpath, name)
            relative = os.path.relpath(path, directory)
            try:
                info = path.lstat()
            except FileNotFoundError:
                continue
            if path.is_symlink():
                content = "link:" + os.readlink(path)
            else:
                old = previous.get(relative)
                if old and old[0] == info.st_size and old[1] == info.st_mtime_ns:
                    content = old[2]
                else:
                    content = file_sha256(path)
            executable = bool(info.st_mode & 0o100)
            stamps[relative] = [info.st_size, info.st_mtime_ns, content, executable]
    digest = hashlib.sha256()
    for relative in sorted(stamps):
        _, _, content, executable = stamps[relative]
        digest.update(f"{relative}\0{content}\0{int(executable)}\n".encode())
    return digest.hexdigest(), stamps


def _tool_identity(name: str) -> str | None:
    found = shutil.which(name)
    if not found:
        return None
    real = os.path.realpath(found)
    info = os.stat(real)
    return f"{real}:{info.st_size}:{info.st_mtime_ns}"


def toolchain_digest(env: dict[str, str], install_base: Path) -> str:
    """Compilers, build tools, Python and underlays (entries inside our own install base left out,
    so building with the workspace itself sourced changes nothing)."""
    own = str(install_base)
    prefixes = {
        name: [p for p in env.get(name, "").split(os.pathsep) if p and not p.startswith(own)]
        for name in PREFIX_VARIABLES
    }
    data = {
        "variables": {name: env.get(name) for name in TOOLCHAIN_VARIABLES},
        "prefixes": prefixes,
        "tools": {name: _tool_identity(name) for name in TOOLS},
        "python": [sys.executable, sys.version],
    }
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()


def combine(parts: dict) -> str:
    return hashlib.sha256(json.dumps(parts, sort_keys=True).encode()).hexdigest()
