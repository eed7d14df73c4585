"""The environment a package builds in: the caller's, plus its dependencies' install hooks."""

from __future__ import annotations

import json
import os
from pathlib import Path

from roc.builder.layout import package_prefix
from roc.buildtypes.context import BuildOptions
from roc.environment import path_list, with_implicit_underlay
from roc.environment.dsv import apply_operations, resolve_operations
from roc.workspace.package import Package

ENVIRONMENT_FILE = "roc_build_environment.json"


def base_environment() -> dict[str, str]:
    """The calling environment, on roc's implicit underlay when no ROS environment is sourced."""
    return with_implicit_underlay(os.environ)


def build_environment(package: Package, dependencies: list[str], options: BuildOptions) -> dict[str, str]:
    """The base environment plus the install hooks of ``dependencies`` (in dependency order)."""
    env = base_environment()
    # rosidl's generators list a message's includes from Python sets, whose order follows the string hash
    # seed: a fixed seed makes the generated sources the same in every build, so a compiler cache hits
    env.setdefault("PYTHONHASHSEED", "0")
    for name in dependencies:
        prefix = package_prefix(options.install_base, name, options.merge_install)
        dsv = prefix / "share" / name / "package.dsv"
        if dsv.is_file():
            apply_operations(env, prefix, resolve_operations(prefix, dsv))
    if package.type == "ros.ament_cmake":
        # As colcon-ros does: CMake finds ament packages of every AMENT_PREFIX_PATH entry.
        cmake_paths = path_list(env.get("CMAKE_PREFIX_PATH"))
        extra = [p for p in path_list(env.get("AMENT_PREFIX_PATH")) if p not in cmake_paths]
        env["CMAKE_PREFIX_PATH"] = os.pathsep.join(cmake_paths + extra)
    return env


def saved_environment(build_base: Path, name: str) -> dict[str, str] | None:
    """The environment of the package's last build, if it was built."""
    path = build_base / name / ENVIRONMENT_FILE
    return json.loads(path.read_text()) if path.is_file() else None
