"""After a package is installed: its hooks, package scripts and colcon-core marker, as colcon makes them."""

from __future__ import annotations

import shutil
from pathlib import Path

from roc.fsutil import write_text_atomic
from roc.handlers.python import python_lib
from roc.shell.scripts import write_hook, write_package_scripts
from roc.workspace.package import Package

CONFIG_DIRS = ("share/*/cmake", "lib/cmake/*", "lib64/cmake/*", "share/*", "cmake")


def _has_cmake_config(prefix: Path) -> bool:
    return any(
        path.name.endswith(("Config.cmake", "-config.cmake"))
        for pattern in CONFIG_DIRS for directory in prefix.glob(pattern) if directory.is_dir()
        for path in directory.iterdir()
    )


def _has_shared_libraries(prefix: Path) -> bool:
    lib = prefix / "lib"
    return lib.is_dir() and any(".so" in p.name and p.is_file() for p in lib.iterdir())


def finish_package(package: Package, prefix: Path) -> None:
    name = package.name
    hooks: list[str] = []

    def hook(hook_name: str, line: str) -> None:
        hooks.append(write_hook(prefix, name, hook_name, line))

    cmake_based = package.build_type in ("cmake", "ament_cmake")
    if cmake_based and _has_cmake_config(prefix):
        hook("cmake_prefix_path", "prepend-non-duplicate;CMAKE_PREFIX_PATH;")
    if _has_shared_libraries(prefix):
        hook("ld_library_path_lib", "prepend-non-duplicate;LD_LIBRARY_PATH;lib")
    if (prefix / "bin").is_dir():
        if package.type == "cmake":
            hook("path", "prepend-non-duplicate;PATH;bin")
        hook("pythonscriptspath", "prepend-non-duplicate;PATH;bin")
    if (prefix / "lib" / "pkgconfig").is_dir():
        hook("pkg_config_path", "prepend-non-duplicate;PKG_CONFIG_PATH;lib/pkgconfig")
    site_packages = python_lib(prefix)
    if site_packages.is_dir() and any(site_packages.iterdir()):
        hook("pythonpath", f"prepend-non-duplicate;PYTHONPATH;{site_packages.relative_to(prefix)}")
    if package.type in ("ros.ament_python", "ros.cmake"):
        hook("ament_prefix_path", "prepend-non-duplicate;AMENT_PREFIX_PATH;")
    if package.type == "ros.cmake":
        _register_ros_package(package, prefix)
    write_package_scripts(prefix, name, hooks)
    run_dependencies = sorted(package.dependencies.get("run", set()) - {name})
    write_text_atomic(prefix / "share" / "colcon-core" / "packages" / name, ":".join(run_dependencies))


def _register_ros_package(package: Package, prefix: Path) -> None:
    """A plain CMake package with a package.xml gets the ament index entry and its manifest installed."""
    write_text_atomic(prefix / "share" / "ament_index" / "resource_index" / "packages" / package.name, "")
    if package.manifest is not None:
        target = prefix / "share" / package.name / "package.xml"
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(package.manifest.path, target)
