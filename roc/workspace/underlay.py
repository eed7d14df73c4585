"""Packages of the underlay workspaces (``AMENT_PREFIX_PATH``, ``COLCON_PREFIX_PATH``), and two checks
before a build: colcon-override-check's (building a package that an underlay also has, while another
underlay package uses it, is risky: include order, API/ABI compatibility; reported unless allowed with
``--allow-overriding``), and dependencies that exist nowhere (likely typos)."""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Mapping
from pathlib import Path

from roc.environment import path_list
from roc.workspace.package import CATEGORIES

AMENT_INDEX = Path("share", "ament_index", "resource_index", "packages")
COLCON_INDEX = Path("share", "colcon-core", "packages")


def _names(directory: Path) -> list[str]:
    try:
        return [n for n in os.listdir(directory) if not n.startswith(".")]
    except OSError:
        return []


def underlay_packages(environ: Mapping[str, str]) -> dict[str, list[Path]]:
    """{package name: [install prefixes holding it]} of the sourced underlays."""
    found: dict[str, list[Path]] = {}

    def add(name: str, prefix: Path) -> None:
        if prefix not in found.setdefault(name, []):
            found[name].append(prefix)

    for prefix in path_list(environ.get("AMENT_PREFIX_PATH")):
        for name in _names(Path(prefix) / AMENT_INDEX):
            add(name, Path(prefix))
    for base in path_list(environ.get("COLCON_PREFIX_PATH")):
        for name in _names(Path(base) / COLCON_INDEX):  # a merged install base
            add(name, Path(base))
        for name in _names(Path(base)):  # an isolated one: BASE/NAME/share/colcon-core/packages/NAME
            if (Path(base) / name / COLCON_INDEX / name).is_file():
                add(name, Path(base) / name)
    return found


def _run_dependencies(name: str, prefix: Path) -> set[str]:
    """What an installed package needs at run time: colcon's package index entry, else its package.xml."""
    index = prefix / COLCON_INDEX / name
    if index.is_file():
        return set(path_list(index.read_text().strip()))
    manifest = prefix / "share" / name / "package.xml"
    if not manifest.is_file():
        return set()
    from roc.errors import ManifestError
    from roc.workspace.conditions import condition_environment
    from roc.workspace.manifest import parse_manifest

    try:
        return set(parse_manifest(manifest, condition_environment(os.environ)).category_dependencies()["run"])
    except ManifestError:  # an underlay's broken manifest is not this workspace's problem
        return set()


def overridden_packages(selected: Iterable[str], install_base: Path, allowed: Iterable[str],
                        environ: Mapping[str, str]) -> dict[str, list[Path]]:
    """Selected packages that an underlay also has and that another underlay package depends on at run
    time (an unused or leaf package is harmless): {name: underlay prefixes}, minus ``allowed``."""
    selected = set(selected)
    install_base = install_base.resolve()
    underlay: dict[str, list[Path]] = {}
    built = set(selected)  # packages of this workspace, being built or built before
    for name, prefixes in underlay_packages(environ).items():
        ours = [p for p in prefixes if p.resolve() == install_base or install_base in p.resolve().parents]
        if ours:
            built.add(name)
        if len(ours) < len(prefixes):
            underlay[name] = [p for p in prefixes if p not in ours]
    built.update(_names(install_base / COLCON_INDEX))
    built.update(n for n in _names(install_base) if (install_base / n / COLCON_INDEX / n).is_file())
    candidates = (selected & set(underlay)) - set(allowed)
    if not candidates:
        return {}
    used = set()
    for name, prefixes in underlay.items():
        if name not in built:
            for prefix in prefixes:
                used |= _run_dependencies(name, prefix) & candidates
    return {name: underlay[name] for name in sorted(used)}


def override_warning(overridden: Mapping[str, list[Path]]) -> str:
    """The warning colcon-override-check prints, in roc's words."""
    where = "".join(f"\n  '{name}' is in: {', '.join(map(str, prefixes))}" for name, prefixes in overridden.items())
    return ("some selected packages are already installed in an underlay workspace and used there:" + where +
            "\nIf an overridden package installs headers, every package of this workspace must put its include "
            "directories in workspace order, or builds may fail or behave in undefined ways at run time. "
            "If another underlay package uses it, the overriding package must be API and ABI compatible with "
            "the one it replaces.\nIf you understand the risks, add to the command line: --allow-overriding "
            + " ".join(overridden))


# What a ROS package may be called (REP 144). A rosdep key of a system package often cannot be
# (python3-numpy, libboost-dev), and is never reported as missing.
PACKAGE_NAME = re.compile(r"[a-z][a-z0-9_]*")


def missing_dependencies(packages: Iterable, known: set[str],
                         categories: tuple[str, ...] = CATEGORIES) -> dict[str, list[str]]:
    """{name: [packages depending on it]} for each dependency of ``packages`` (roc.workspace.package
    Packages) in ``categories`` that is not ``known`` (the workspace's and the underlays' packages) and
    could be a ROS package's name."""
    missing: dict[str, list[str]] = {}
    for package in packages:
        for name in sorted(package.direct_dependencies(categories)):
            if name not in known and PACKAGE_NAME.fullmatch(name):
                missing.setdefault(name, []).append(package.name)
    return missing

