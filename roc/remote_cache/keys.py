"""Remote cache keys: a package's fingerprint parts (roc.builder.uptodate) made portable between
machines and checkouts.

The local fingerprint names tools by path, size and mtime and underlay packages by change time: cheap,
but different on every machine. The remote key names them by content instead (a tool's SHA-256, an
underlay package's package.xml, or every file of an underlay package installed in its own prefix),
uses the dependencies' remote keys, and adds the platform. Sources, options (the install layout
among them) and build variables count as they do locally. The absolute install prefix is not in the
key: an entry is uploaded under this key only when its files do not depend on where it was built
(roc.builder.artefact rewrites the few that may); otherwise under ``placed_key``, which adds the
workspace's paths.
"""

from __future__ import annotations

import functools
import hashlib
import os
import platform
import shutil
import sys
from pathlib import Path

from roc.builder.artefact import Places
from roc.builder.fingerprint import REGENERATED_INSTALL_FILES, combine, underlay_location
from roc.builder.state import read_state
from roc.fsutil import file_sha256

FORMAT = 1  # raise when the archive or the key's parts change meaning


@functools.cache
def tool_content(name: str, path: str | None) -> str | None:
    """A program found on PATH, by its real name and content."""
    found = shutil.which(name, path=path)
    if not found:
        return None
    real = os.path.realpath(found)
    return f"{os.path.basename(real)}:{file_sha256(Path(real))}"


def _prefix_content(prefix: str) -> str:
    """Every installed file of a package in its own prefix, by content (scripts a build regenerates
    left out)."""
    digest = hashlib.sha256()
    for dirpath, dirnames, filenames in sorted(os.walk(prefix)):
        dirnames.sort()
        for name in sorted(filenames):
            path = os.path.join(dirpath, name)
            relative = os.path.relpath(path, prefix)
            if not REGENERATED_INSTALL_FILES.search(relative) and os.path.isfile(path):
                digest.update(f"{relative}\0{file_sha256(Path(path))}\0".encode())
    return digest.hexdigest()


@functools.cache
def underlay_content(name: str, prefixes: tuple[str, ...]) -> str | None:
    """An underlay package by content: its package.xml in a shared prefix (/opt/ros, a venv), all of
    its files in a prefix of its own. None when no underlay has it."""
    found = underlay_location(name, prefixes)
    if found is None:
        return None
    prefix, manifest = found
    if manifest is None:
        return f"{prefix}:files:{_prefix_content(prefix)}"
    return f"{prefix}:package.xml:{file_sha256(Path(manifest))}"


def portable_toolchain(toolchain: dict[str, object], path: str | None) -> dict[str, object]:
    """Toolchain parts (roc.builder.fingerprint.toolchain_parts) with each tool by content, not by path
    and time stamp."""
    return {part: tool_content(part.removeprefix("tool "), path) if part.startswith("tool ") else value
            for part, value in toolchain.items()}


def platform_parts() -> dict[str, object]:
    return {"system": sys.platform, "machine": platform.machine(), "libc": list(platform.libc_ver())}


class RemoteKeys:
    """The remote key of each package, computed in dependency order from its fingerprint parts. A
    package that is not computed in this run counts with the remote key recorded at its last build
    (what is installed); without one, its dependents have no remote key (they are built locally)."""

    def __init__(self, environment: dict[str, str], prefixes: list[str], build_base: Path):
        self.path = environment.get("PATH")
        self.prefixes = tuple(prefixes)
        self.build_base = build_base
        self.keys: dict[str, str | None] = {}

    def dependency_key(self, name: str) -> str | None:
        """The remote key of a package computed in this run, else the one its last build recorded."""
        if name in self.keys:
            return self.keys[name]
        return read_state(self.build_base / name).get("remote_key")

    def key(self, name: str, parts: dict) -> str | None:
        portable = self.portable_parts(parts)
        self.keys[name] = None if portable is None else combine(portable)
        return self.keys[name]

    def portable_parts(self, parts: dict) -> dict | None:
        """What the key of a package with these fingerprint parts is made of (None: a dependency has
        no key)."""
        dependencies = {dependency: self.dependency_key(dependency) for dependency in parts["dependencies"]}
        if None in dependencies.values():
            return None
        return {**parts, "dependencies": dependencies, "toolchain": portable_toolchain(parts["toolchain"], self.path),
                "underlay": {n: underlay_content(n, self.prefixes) for n in parts["underlay"]},
                "platform": platform_parts(), "format": FORMAT}

    def missing_dependency(self, parts: dict) -> str | None:
        """The first dependency without a remote key (why a package has none)."""
        return next((d for d in parts["dependencies"] if self.dependency_key(d) is None), None)


def placed_key(key: str, places: Places) -> str:
    """The key of an entry that only works at the paths it was built at."""
    return combine({"key": key, "places": places.as_dict()})
