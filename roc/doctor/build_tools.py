"""The checks of ``roc doctor`` that builds can work before a CMake error says otherwise: cmake and a C++
compiler on PATH, and the Python that ament_cmake's CMake will find able to import ament_package and
catkin_pkg (ament_cmake runs them at configure)."""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Mapping
from pathlib import Path

from roc import distribution as ros_distribution
from roc.ament_index import resources
from roc.doctor.findings import Finding
from roc.environment import path_list, with_implicit_underlay

CATEGORY = "environment"
COMPILERS = ("c++", "g++", "clang++")
# what ament_cmake imports at configure -> what installs it in a venv ({distro}: the ROS distribution)
AMENT_MODULES = {"ament_package": "ros-{distro}-ament-package", "catkin_pkg": "catkin-pkg"}
_MISSING_MODULES = """
import importlib.util, sys
print(" ".join(name for name in sys.argv[1:] if importlib.util.find_spec(name) is None))
"""


def tools(env: Mapping[str, str]) -> Finding:
    """cmake and a C++ compiler ($CXX, else c++, g++ or clang++) on PATH."""
    path = env.get("PATH", "")
    missing = [] if shutil.which("cmake", path=path) else ["cmake"]
    compiler = env.get("CXX") or next((name for name in COMPILERS if shutil.which(name, path=path)), None)
    if compiler is None or not shutil.which(compiler.split()[0], path=path):
        missing.append(f"a C++ compiler ({compiler}, from CXX)" if compiler else "a C++ compiler")
    if missing:
        return Finding(CATEGORY, "build tools", "warning", f"{' and '.join(missing)} not found on PATH: ament_cmake "
                       "and cmake packages cannot build", "sudo apt install cmake g++ (Debian, Ubuntu)")
    return Finding(CATEGORY, "build tools", "ok", f"cmake, {compiler}")


def cmake_python(env: Mapping[str, str]) -> Path | None:
    """The python3 CMake's FindPython3 picks for ament_cmake, as it searches: the active venv
    (VIRTUAL_ENV), then the bin folder of each CMake prefix (roc adds AMENT_PREFIX_PATH's), then PATH."""
    folders = [Path(env["VIRTUAL_ENV"]) / "bin"] if env.get("VIRTUAL_ENV") else []
    prefixes = path_list(env.get("CMAKE_PREFIX_PATH")) + path_list(env.get("AMENT_PREFIX_PATH"))
    folders += [Path(prefix) / "bin" for prefix in prefixes] + [Path(folder) for folder in path_list(env.get("PATH"))]
    for folder in folders:
        candidate = folder / "python3"
        if candidate.is_file() and os.access(candidate, os.X_OK):
            return candidate
    return None


def ament_python(env: Mapping[str, str]) -> Finding:
    """Whether the Python ament_cmake will run (cmake_python, in the environment a build gets) imports
    ament_package and catkin_pkg: without them every ament_cmake package fails at configure."""
    if "ament_cmake" not in resources("packages"):
        return Finding(CATEGORY, "ament python", "ok", "no ament_cmake installed: nothing to check")
    build_env = with_implicit_underlay(env)
    python = cmake_python(build_env)
    if python is None:
        return Finding(CATEGORY, "ament python", "warning", "no python3 on PATH: ament_cmake packages cannot "
                       "configure", "sudo apt install python3 (Debian, Ubuntu)")
    try:
        result = subprocess.run([str(python), "-c", _MISSING_MODULES, *AMENT_MODULES], env=dict(build_env),
                                capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired) as error:
        return Finding(CATEGORY, "ament python", "warning", f"{python} did not run: {error}",
                       "check the python3 that PATH finds first")
    missing = result.stdout.split() if result.returncode == 0 else list(AMENT_MODULES)
    if not missing:
        return Finding(CATEGORY, "ament python", "ok", f"{python} imports {' and '.join(AMENT_MODULES)}")
    return Finding(CATEGORY, "ament python", "error", f"{python}, the Python ament_cmake's CMake finds, cannot "
                   f"import {' and '.join(missing)}: every ament_cmake package fails at configure",
                   install_command(python, missing, env), details={"python": str(python), "missing": missing})


def install_command(python: Path, modules: list[str], env: Mapping[str, str]) -> str:
    """How to give ``python`` the missing modules: pip in a venv (the ROS wheels' own name for
    ament_package), else the ROS environment and Debian's package."""
    if (python.parent.parent / "pyvenv.cfg").is_file():
        found = ros_distribution.detected(env)
        distro = found[0] if found else "jazzy"
        return f"{python} -m pip install " + " ".join(AMENT_MODULES[name].format(distro=distro) for name in modules)
    steps = []
    if "ament_package" in modules:
        steps.append("source your ROS 2 setup script (/opt/ros/<distro>/setup.bash: its PYTHONPATH has ament_package)")
    if "catkin_pkg" in modules:
        steps.append("sudo apt install python3-catkin-pkg-modules")
    return "; ".join(steps)
