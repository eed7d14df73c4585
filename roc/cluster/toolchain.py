"""A machine's toolchain fingerprint: what a cluster worker must share with the client for the
packages it builds to be what the client's remote keys promise.

It covers what the remote keys (roc.remote_cache.keys) take from the machine rather than from the
workspace: the build variables (CC, CXX, CFLAGS, ...), the underlay prefix paths, the tools of a
CMake build (cmake, make, the compilers) and Python by content, every underlay package by its
package.xml, and the platform. A worker advertises it as a Dask resource (``resource_name``), so
that the scheduler gives a task only to a worker with the client's fingerprint; the worker checks it
again, and the package's whole remote key, before building (roc.cluster.work).
"""

from __future__ import annotations

import functools
import hashlib
import os
from pathlib import Path

from roc.builder.environment import base_environment
from roc.builder.fingerprint import build_tools, combine, toolchain_parts, underlay_prefixes
from roc.fsutil import file_sha256
from roc.remote_cache.keys import platform_parts, portable_toolchain

RESOURCE_PREFIX = "roc-toolchain-"
BUILD_RESOURCE = "roc-build"  # one unit per package a worker builds or tests at once


def _underlay_manifests(prefix: str) -> str:
    """Every package.xml installed in the prefix, by content."""
    digest = hashlib.sha256()
    share = Path(prefix, "share")
    for manifest in sorted(share.glob("*/package.xml")) if share.is_dir() else ():
        digest.update(f"{manifest.parent.name}\0{file_sha256(manifest)}\0".encode())
    return digest.hexdigest()


def fingerprint_parts(environment: dict[str, str], own: Path) -> dict:
    """The parts of the fingerprint of the machine with this build environment; ``own`` is the
    workspace's install base (or a worker's root), whose entries on the prefix paths do not count."""
    prefixes = underlay_prefixes(environment, own)
    tools = build_tools("cmake", environment, ())
    return {
        "toolchain": portable_toolchain(toolchain_parts(environment, own, tools), environment.get("PATH")),
        "underlays": {prefix: _underlay_manifests(prefix) for prefix in prefixes if os.path.isdir(prefix)},
        "platform": platform_parts(),
    }


def fingerprint(environment: dict[str, str], own: Path) -> str:
    return combine(fingerprint_parts(environment, own))[:16]


def client_fingerprint(install_base: Path) -> tuple[str, dict]:
    """This build's fingerprint and its parts (a workspace with this install base)."""
    parts = fingerprint_parts(base_environment(), install_base)
    return combine(parts)[:16], parts


@functools.cache
def machine_fingerprint(own: Path) -> str:
    """This process's fingerprint (computed once: a worker's toolchain does not change while it runs)."""
    return fingerprint(base_environment(), own)


def resource_name(digest: str) -> str:
    return f"{RESOURCE_PREFIX}{digest}"


def differences(mine: dict, theirs: dict) -> list[str]:
    """The parts of two fingerprints that differ, as ``toolchain: tool c++`` (for a refusal)."""
    found = []
    for part in sorted(mine.keys() | theirs.keys()):
        a, b = mine.get(part), theirs.get(part)
        if isinstance(a, dict) and isinstance(b, dict):
            found += [f"{part}: {name}" for name in sorted(a.keys() | b.keys()) if a.get(name) != b.get(name)]
        elif a != b:
            found.append(part)
    return found
