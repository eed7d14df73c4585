"""After a package is installed: its hooks, package scripts and colcon-core marker, as colcon makes them.

The hooks, in colcon's order: what the install prefix holds (CMake modules and configs, shared
libraries, executables, pkg-config files, Python modules and scripts), then the hooks of the build type
(ament_python: AMENT_PREFIX_PATH; ros.cmake: PKG_CONFIG_PATH; ament_cmake: the package's own
local_setup scripts), then those a colcon.pkg names.
"""

from __future__ import annotations

import os
from functools import lru_cache
from pathlib import Path

from roc.buildtypes.python import python_lib
from roc.fsutil import write_text_atomic
from roc.shell.scripts import write_hook, write_package_scripts
from roc.workspace.package import Package

LIB_DIRS = ("lib64", "lib32", "libx32", "lib")


def _cmake_module_paths(prefix: Path, name: str) -> list[Path]:
    """Where find_package looks for Find<Name>.cmake modules of this package, as colcon lists them."""
    paths = [prefix / lib / "cmake" / name for lib in LIB_DIRS] + [prefix / "share" / "cmake" / name]
    paths += [prefix / lib / name for lib in LIB_DIRS] + [prefix / "share" / name]
    paths += [prefix / lib / name / sub for sub in ("cmake", "CMake") for lib in LIB_DIRS]
    paths += [prefix / "share" / name / "cmake", prefix / "share" / name / "CMake"]
    return paths


def _has_cmake_config(prefix: Path) -> bool:
    return any(f.endswith(("-config.cmake", "Config.cmake")) for _, _, files in os.walk(prefix) for f in files)


def _has_file(directory: Path) -> bool:
    return directory.is_dir() and any(child.is_file() for child in directory.iterdir())


@lru_cache(maxsize=1)
def multiarch() -> str | None:
    """The multiarch triplet (e.g. x86_64-linux-gnu) that colcon-ros uses for pkg-config paths: Python's
    own (Debian's and most builds know it), else gcc's (a package restored from a cache is finished
    without running a compiler)."""
    import subprocess
    import sysconfig

    known = sysconfig.get_config_var("MULTIARCH")
    if known:
        return str(known)
    try:
        return subprocess.run(["gcc", "-print-multiarch"], capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None


def finish_package(package: Package, prefix: Path) -> None:
    name = package.name
    hooks: list[str] = []

    def hook(hook_name: str, line: str) -> None:
        hooks.extend(write_hook(prefix, name, hook_name, line))

    module_dirs: list[Path] = []
    for directory in _cmake_module_paths(prefix, name):
        if directory.is_dir() and not any(directory.samefile(d) for d in module_dirs) and any(
                f.is_file() and f.name.startswith("Find") and f.name.endswith(".cmake") for f in directory.iterdir()):
            suffix = str(len(module_dirs)) if module_dirs else ""
            module_dirs.append(directory)
            relative = directory.relative_to(prefix)
            hook(f"cmake_module_path{suffix}", f"prepend-non-duplicate;CMAKE_MODULE_PATH;{relative}")
    if _has_cmake_config(prefix):
        hook("cmake_prefix_path", "prepend-non-duplicate;CMAKE_PREFIX_PATH;")
    for lib in sorted(prefix.glob("lib*")):
        if lib.is_dir() and any(lib.glob("*.so")):
            hook(f"ld_library_path_{lib.name}", f"prepend-non-duplicate;LD_LIBRARY_PATH;{lib.name}")
    if _has_file(prefix / "bin"):
        hook("path", "prepend-non-duplicate;PATH;bin")
    if (prefix / "lib" / "pkgconfig" / f"{name}.pc").is_file():
        hook("pkg_config", "prepend-non-duplicate;PKG_CONFIG_PATH;lib/pkgconfig")
    site_packages = python_lib(prefix)
    if site_packages.exists():
        hook("pythonpath", f"prepend-non-duplicate;PYTHONPATH;{site_packages.relative_to(prefix)}")
    if _has_file(prefix / "bin"):
        hook("pythonscriptspath", "prepend-non-duplicate;PATH;bin")
    if package.type == "ros.ament_python":
        hook("ament_prefix_path", "prepend-non-duplicate;AMENT_PREFIX_PATH;")
    if package.type == "ros.cmake":
        hook("pkg_config_path", "prepend-non-duplicate;PKG_CONFIG_PATH;lib/pkgconfig")
        if multiarch():
            hook("pkg_config_path_multiarch", f"prepend-non-duplicate;PKG_CONFIG_PATH;lib/{multiarch()}/pkgconfig")
    if package.type == "ros.ament_cmake":  # its own local_setup for every shell colcon knows, as colcon-ros lists them
        hooks.extend(f"share/{name}/local_setup.{ext}" for ext in ("bash", "dsv", "ps1", "sh", "zsh"))
    hooks.extend(package.hooks)
    write_package_scripts(prefix, name, hooks)
    run_dependencies = sorted(package.dependencies.get("run", set()) - {name})
    write_text_atomic(prefix / "share" / "colcon-core" / "packages" / name, ":".join(run_dependencies))
