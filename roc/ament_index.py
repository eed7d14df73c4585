"""The ament index of every prefix roc looks in (``roc.environment.ament_prefixes``: AMENT_PREFIX_PATH,
the wheels' venv, /opt/ros, sourced overlays, and roc's own environment): installed packages, their
prefixes, executables, share directories and other resources, as ament_index_python and ros2pkg find
them. Plain files: no rclpy, nothing imported from ROS."""

from __future__ import annotations

import os
from pathlib import Path

from roc.environment import ament_prefixes
from roc.errors import RocError
from roc.messages import did_you_mean

RESOURCE_INDEX = Path("share", "ament_index", "resource_index")


def resources(kind: str) -> dict[str, Path]:
    """Resource name -> the first prefix that registers it (earlier prefixes overlay later ones)."""
    found: dict[str, Path] = {}
    for prefix in ament_prefixes():
        try:
            names = os.listdir(prefix / RESOURCE_INDEX / kind)
        except OSError:
            continue
        for name in names:
            if not name.startswith("."):
                found.setdefault(name, prefix)
    return found


def resource_text(kind: str, name: str) -> str | None:
    """The content of resource ``name`` of ``kind``, None when no prefix registers it."""
    prefix = resources(kind).get(name)
    return (prefix / RESOURCE_INDEX / kind / name).read_text() if prefix is not None else None


def packages() -> dict[str, Path]:
    """Every installed package and its prefix."""
    return resources("packages")


class PackageNotFound(RocError):
    """A package the ament index does not have; the message names the closest ones."""

    def __init__(self, name: str, known: dict[str, Path]):
        hint = did_you_mean(name, known, count=1, quote=False) or "run 'roc pkg list' to see the installed packages"
        where = ", ".join(str(p) for p in ament_prefixes()) or "AMENT_PREFIX_PATH is empty"
        super().__init__(f"package '{name}' not found in the ament index ({where}); {hint}")


def package_prefix(name: str) -> Path:
    known = packages()
    if name not in known:
        raise PackageNotFound(name, known)
    return known[name]


def share_directory(name: str) -> Path:
    return package_prefix(name) / "share" / name


def executables(name: str) -> list[Path]:
    """The executable files below ``<prefix>/lib/<name>`` (hidden directories left out), sorted as
    ros2pkg lists them."""
    base = package_prefix(name) / "lib" / name
    found: list[Path] = []
    for directory, subdirectories, files in os.walk(base):
        subdirectories[:] = sorted(d for d in subdirectories if not d.startswith("."))
        for file_name in sorted(files):
            path = Path(directory, file_name)
            if os.access(path, os.X_OK):
                found.append(path)
    return found


def find_executable(package: str, name: str) -> Path:
    """The one executable ``name`` of ``package`` (as ros2 run finds it); an error listing what exists."""
    found = executables(package)
    matches = [path for path in found if path.name == name]
    if len(matches) > 1:
        raise RocError(f"package '{package}' has {len(matches)} executables named '{name}': "
                       f"{', '.join(map(str, matches))}; remove all but one from the install space")
    if not matches:
        names = sorted({path.name for path in found})
        hint = did_you_mean(name, names, count=1)
        listing = f"its executables: {', '.join(names)}" if names else "it installs no executables"
        raise RocError(f"package '{package}' has no executable '{name}'; {hint + ' ' if hint else ''}({listing})")
    return matches[0]
