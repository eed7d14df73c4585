"""The ROS 2 distribution roc works with, and what roc does differently on each one: the one place that
knows how Jazzy and Kilted differ. Every other module asks ``current()`` (or ``of_prefix``, ``sourced``)
instead of guessing.

The distribution is read from the environment, never assumed: the version of the rclpy that the ament
index has first (AMENT_PREFIX_PATH, then roc's own Python environment: roc.environment.ament_prefixes),
else ROS_DISTRO. Two distributions in one environment (an overlay built on one, sourced on top of the
other, chains the first's rclpy in) are a mix (``mix``). roc's build base records the distribution it
was built with (``MARKER``, ``built_with``), so a workspace built on one distribution is not built
again on the other. A mix is refused before rclpy is loaded (``refuse_mix``, called by roc.rclpy_guard
where rclpy is imported): one distribution's rclpy on the other's libraries crashes the process. Plain
files: no rclpy, nothing imported from ROS."""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from pathlib import Path

from roc.environment import ament_prefixes
from roc.errors import RocError

MARKER = ".roc_ros_distribution"  # in a build base roc built in: the distribution's name


class Distribution:
    """A ROS 2 distribution and the facts about it that roc acts on. A plain class: every command that
    reads package conditions imports this module, and dataclasses would cost each some 8 ms."""

    __slots__ = ("name", "fastdds_major", "profiles_variable")

    def __init__(self, name: str, fastdds_major: int, profiles_variable: str):
        self.name = name
        # 2: Fast DDS 2 (Jazzy's libfastrtps), 3: Fast DDS 3 (Kilted's libfastdds)
        self.fastdds_major = fastdds_major
        # the variable Fast DDS reads its XML profiles file from (Kilted's rmw warns about Fast DDS 2's)
        self.profiles_variable = profiles_variable

    def renamed(self, name: str) -> Distribution:
        return Distribution(name, self.fastdds_major, self.profiles_variable)

    def __repr__(self) -> str:
        return f"Distribution({self.name!r}, fastdds_major={self.fastdds_major})"


JAZZY = Distribution("jazzy", fastdds_major=2, profiles_variable="FASTRTPS_DEFAULT_PROFILES_FILE")
KILTED = Distribution("kilted", fastdds_major=3, profiles_variable="FASTDDS_DEFAULT_PROFILES_FILE")
SUPPORTED = (JAZZY, KILTED)
# rclpy's major version in each distribution since Humble (how a sourced rclpy tells its distribution;
# ROS 2 from PyPI wheels sets no ROS_DISTRO)
RCLPY_MAJORS = {3: "humble", 4: "iron", 7: "jazzy", 9: "kilted"}
END_OF_LIFE = ("ardent", "bouncy", "crystal", "dashing", "eloquent", "foxy", "galactic", "iron")


def named(name: str) -> Distribution:
    """The facts for distribution ``name``: its own when roc knows it; an older one gets Jazzy's, a newer
    (or unknown) one the newest roc knows, under its own name."""
    for known in SUPPORTED:
        if known.name == name:
            return known
    older = {"humble", "iron", *END_OF_LIFE}
    return (JAZZY if name in older else SUPPORTED[-1]).renamed(name)


def rclpy_version(prefix: Path) -> str | None:
    """The version of the rclpy installed in ``prefix`` (its package.xml), None when it has none."""
    try:
        text = (prefix / "share" / "rclpy" / "package.xml").read_text()
    except OSError:
        return None
    found = re.search(r"<version>\s*([^<\s]+)\s*</version>", text)
    return found.group(1) if found else None


def of_rclpy(version: str) -> str | None:
    """The distribution an rclpy version shipped with, None when roc does not know it."""
    major = version.split(".")[0]
    return RCLPY_MAJORS.get(int(major)) if major.isdigit() else None


def _rclpys(environ: Mapping[str, str]) -> list[tuple[str, str]]:
    """(distribution, where) of each rclpy of the ament index, in its order."""
    found = []
    for prefix in ament_prefixes(environ):
        version = rclpy_version(prefix)
        name = of_rclpy(version) if version else None
        if name:
            found.append((name, f"rclpy {version} in {prefix}"))
    return found


def sourced(environ: Mapping[str, str] | None = None) -> list[tuple[str, str]]:
    """Every (distribution, where it comes from) the environment shows: ROS_DISTRO, and each rclpy of
    the ament index (roc's own environment included). More than one name among them is a mix."""
    environ = os.environ if environ is None else environ
    named_by_variable = [(environ["ROS_DISTRO"].lower(), "ROS_DISTRO")] if environ.get("ROS_DISTRO") else []
    return [*named_by_variable, *_rclpys(environ)]


def detected(environ: Mapping[str, str] | None = None) -> tuple[str, str] | None:
    """(distribution, why) of the ROS 2 roc works with: that of the first rclpy of the ament index (what
    nodes and roc itself import), else ROS_DISTRO; None when neither exists."""
    environ = os.environ if environ is None else environ
    found = _rclpys(environ)
    if found:
        return found[0]
    return (environ["ROS_DISTRO"].lower(), "ROS_DISTRO") if environ.get("ROS_DISTRO") else None


def current(environ: Mapping[str, str] | None = None) -> Distribution:
    """The distribution roc acts for (``detected``); Jazzy when no ROS 2 is found."""
    found = detected(environ)
    return named(found[0]) if found else JAZZY


def mix(environ: Mapping[str, str] | None = None) -> str | None:
    """Two distributions the environment mixes (``sourced``), named with where each comes from (``jazzy
    (rclpy 7.1.5 in /opt/ros/jazzy) and kilted (ROS_DISTRO)``); None when it has one at most."""
    seen = sourced(environ)
    names = list(dict.fromkeys(name for name, _ in seen))
    if len(names) < 2:
        return None
    first, second = (next(where for name, where in seen if name == n) for n in names[:2])
    return f"{names[0]} ({first}) and {names[1]} ({second})"


class MixedDistributions(RocError):
    """Two ROS 2 distributions are sourced (``mix``)."""


def refuse_mix(environ: Mapping[str, str] | None = None) -> None:
    """Raise MixedDistributions when the environment mixes two distributions."""
    mixed = mix(environ)
    if mixed:
        raise MixedDistributions(f"two ROS 2 distributions are sourced: {mixed}; use a new shell that sources "
                                 "one of them, and only workspaces built on it")


def built_with(build_base: Path) -> str | None:
    """The distribution roc built in ``build_base`` with, None when it did not say."""
    try:
        return (build_base / MARKER).read_text().strip() or None
    except OSError:
        return None
