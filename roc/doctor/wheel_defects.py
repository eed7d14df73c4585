"""The checks of ``roc doctor`` for defects of ROS 2's PyPI wheels that no file edit repairs (the CMake
files' are ``wheel_repairs``): packages an ament_cmake build needs that the meta wheels do not pull in,
and librcl linking one middleware directly, so that RMW_IMPLEMENTATION alone cannot choose another."""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path

from roc import distribution as ros_distribution
from roc import middleware
from roc.doctor.findings import Finding
from roc.environment import ament_prefixes

CATEGORY = "environment"
AMENT_INDEX = Path("share") / "ament_index" / "resource_index" / "packages"
# packages that installed packages name as <buildtool_export_depend> (builds on them need them) but whose
# wheels do not depend on them (requirements/ros-jazzy.txt installs them for roc's own set-up). Which are
# needed follows the installed package.xml files: Kilted's rosidl_generator_py needs no python_cmake_module.
FORGOTTEN = ("ament_package", "ament_cmake_include_directories", "rosidl_core_generators", "python_cmake_module",
             "ament_cmake_gmock", "ament_cmake_gtest", "ament_cmake_pytest")
_EXPORTED_TOOL = re.compile(r"<buildtool_export_depend[^>]*>\s*([\w-]+)\s*</buildtool_export_depend>")


def wheel_prefixes() -> list[Path]:
    """The ament prefixes that are Python venvs, as the ROS 2 wheels install into (an apt install is not)."""
    return [prefix for prefix in ament_prefixes() if (prefix / "pyvenv.cfg").is_file()]


def _installed(prefix: Path) -> set[str]:
    try:
        return {entry.name for entry in (prefix / AMENT_INDEX).iterdir() if not entry.name.startswith(".")}
    except OSError:
        return set()


def needed(prefix: Path, installed: set[str]) -> set[str]:
    """The FORGOTTEN packages that the packages installed in ``prefix`` name as build tools of their users."""
    names: set[str] = set()
    for package in installed:
        try:
            text = (prefix / "share" / package / "package.xml").read_text(encoding="utf-8")
        except OSError:
            continue
        names.update(name for name in _EXPORTED_TOOL.findall(text) if name in FORGOTTEN)
    return names


def missing_packages(env: Mapping[str, str], prefixes: list[Path] | None = None) -> Finding:
    """Packages builds need that are missing from a venv of ROS 2 wheels, with the pip command that adds them."""
    found = ros_distribution.detected(env)
    distro = found[0] if found else "jazzy"
    commands, names = [], []
    for prefix in wheel_prefixes() if prefixes is None else prefixes:
        installed = _installed(prefix)
        missing = sorted(needed(prefix, installed) - installed)
        if missing:
            names += missing
            wheels = " ".join(f"ros-{distro}-{name.replace('_', '-')}" for name in missing)
            commands.append(f"{prefix / 'bin' / 'python'} -m pip install {wheels}")
    if not names:
        return Finding(CATEGORY, "wheel packages", "ok", "every package ament_cmake builds need is installed")
    return Finding(CATEGORY, "wheel packages", "error", f"the ROS 2 wheels lack {len(names)} package(s) builds need "
                   f"(their meta wheels do not install them): {', '.join(names)}", "; ".join(commands),
                   details={"missing": names})


def linked_rmw(env: Mapping[str, str], prefixes: list[Path] | None = None) -> Finding:
    """The middleware librcl links directly (the ROS 2 wheels'), and whether roc can still give its processes
    the one RMW_IMPLEMENTATION names (roc.middleware: loaded first, LD_PRELOAD for the nodes it starts)."""
    for prefix in ament_prefixes() if prefixes is None else prefixes:
        librcl = prefix / "lib" / "librcl.so"
        if not librcl.is_file():
            continue
        linked = middleware.linked_middleware(librcl)
        if linked is None:
            return Finding(CATEGORY, "linked rmw", "ok", "librcl loads the middleware RMW_IMPLEMENTATION names")
        chosen = env.get("RMW_IMPLEMENTATION")
        details = {"librcl": str(librcl), "linked": linked}
        if chosen and chosen != linked:
            library = middleware.installed(env).get(chosen)
            if library is None or not library.is_file():
                return Finding(CATEGORY, "linked rmw", "error", f"{librcl} links {linked} directly (the ROS 2 "
                               f"wheels do) and RMW_IMPLEMENTATION={chosen} is not installed",
                               f"source the setup script of the workspace that built {chosen} (see roc's "
                               f"middlewares page), or unset RMW_IMPLEMENTATION to use {linked}", details=details)
            return Finding(CATEGORY, "linked rmw", "info", f"{librcl} links {linked} directly (the ROS 2 wheels "
                           f"do): roc loads {chosen} first for itself and the nodes roc run and roc launch start; "
                           f"other programs need LD_PRELOAD={library}", details={**details, "library": str(library)})
        return Finding(CATEGORY, "linked rmw", "ok", f"{linked}, which librcl links directly (ROS 2 wheels); "
                       "roc gives its processes another one that RMW_IMPLEMENTATION names and the ament index has")
    return Finding(CATEGORY, "linked rmw", "ok", "no librcl found")
