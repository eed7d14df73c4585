"""Find the packages of a workspace with colcon's rules.

``--base-paths`` are crawled recursively (default ``.``): the crawl stops at a package, skips hidden
directories, follows symlinks once (by real path) and prunes ignored directories. ``--paths`` name
package directories directly (shell wildcards allowed; entries that are not directories are ignored,
as in colcon). Either replaces the default base path.
"""

from __future__ import annotations

import glob
import os
import re
from collections.abc import Iterable, Mapping
from pathlib import Path

from roc.errors import RocError, UsageError
from roc.workspace.identify import SkipLocation, identify
from roc.workspace.package import IGNORE_MARKERS, Package


def _expand(patterns: Iterable[str], root: Path) -> list[str]:
    """Expand shell wildcards (for values that did not go through a shell), keeping directories."""
    result: list[str] = []
    for pattern in patterns:
        if any(c in pattern for c in "*?["):
            matches = sorted(glob.glob(str(root / pattern)))
            result.extend(os.path.relpath(m, root) if not os.path.isabs(pattern) else m
                          for m in matches if os.path.isdir(m))
        else:
            result.append(pattern)
    return result


def discover_packages(
    root: Path,
    variables: Mapping[str, str],
    base_paths: list[str] | None = None,
    paths: list[str] | None = None,
    visited: list[str] | None = None,
) -> list[Package]:
    """All packages below ``root`` (relative base paths and paths are taken from ``root``).

    ``visited`` collects every directory looked at (for the discovery cache)."""
    visited = [] if visited is None else visited
    if base_paths is None and paths is None:
        base_paths = ["."]
    found: dict[str, Package] = {}  # real path -> package
    # Base paths first: a package found both ways keeps its crawled path, as in colcon.
    for base in _expand(base_paths or [], root):
        start = root / base
        if not start.is_dir():
            raise UsageError(f"--base-paths: '{base}' is not a directory")
        _crawl(start, Path(base), variables, found, visited)
    for given in _expand(paths or [], root):
        directory = root / given
        if not directory.is_dir():  # e.g. files of a shell-expanded 'src/repo/*': colcon ignores them
            continue
        real = os.path.realpath(directory)
        visited.append(str(directory))
        if real in found:
            continue
        try:
            # colcon shows --paths packages by absolute path (normalised, symlinks kept)
            package = identify(directory, Path(os.path.abspath(directory)), set(os.listdir(directory)), variables)
        except SkipLocation:
            continue
        if package:
            found[real] = package
    packages = sorted(found.values(), key=lambda p: (p.name, str(p.path)))
    _check_names(packages)
    _check_duplicates(packages)
    _resolve_groups(packages)
    return packages


def _crawl(start: Path, shown_base: Path, variables, found: dict[str, Package], visited: list[str]) -> None:
    seen: set[str] = set()
    for dirpath, dirnames, filenames in os.walk(start, followlinks=True):
        real = os.path.realpath(dirpath)
        if real in seen or real in found:
            dirnames.clear()
            continue
        seen.add(real)
        visited.append(dirpath)
        shown = shown_base / os.path.relpath(dirpath, start)
        try:
            package = identify(Path(dirpath), shown, set(filenames), variables)
        except SkipLocation:
            markers = [os.path.join(dirpath, m) for m in IGNORE_MARKERS if m in filenames]
            if markers:  # only the marker matters, not what changes below it (e.g. log/ during builds)
                visited[-1:] = markers
            dirnames.clear()
            continue
        if package:
            found[real] = package
            dirnames.clear()
            continue
        dirnames[:] = sorted(d for d in dirnames if not d.startswith("."))


# Names become directory names and go into shell scripts: no separators, spaces or shell syntax.
_VALID_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.+-]*")


def _check_names(packages: list[Package]) -> None:
    for package in packages:
        if not _VALID_NAME.fullmatch(package.name):
            raise RocError(
                f"{package.path}: package name '{package.name}' is not usable; names may hold letters, "
                "digits and _ . + - only (see the name in its package.xml, CMakeLists.txt, setup.py or colcon.pkg)"
            )


def _check_duplicates(packages: list[Package]) -> None:
    by_name: dict[str, list[Package]] = {}
    for package in packages:
        by_name.setdefault(package.name, []).append(package)
    for name, same in by_name.items():
        if len(same) > 1:
            where = " and ".join(str(p.path) for p in same)
            raise RocError(
                f"duplicate package name '{name}' in {where}; rename one, or put a COLCON_IGNORE file "
                f"in the directory of the one to leave out"
            )


def _resolve_groups(packages: list[Package]) -> None:
    """A ``group_depend`` on a group depends (build and run) on every package that is a member of it."""
    members: dict[str, set[str]] = {}
    for package in packages:
        for group in package.member_of_groups:
            members.setdefault(group, set()).add(package.name)
    for package in packages:
        for group in package.group_depends:
            names = members.get(group, set()) - {package.name}
            if names:
                package.dependencies.setdefault("build", set()).update(names)
                package.dependencies.setdefault("run", set()).update(names)
