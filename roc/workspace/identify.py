"""Decide whether a directory is a package, and of which type, with colcon's precedence:

1. ``COLCON_IGNORE`` prunes the directory.
   Catkin and ament_tools install spaces (``_setup_util.py``, ``_order_isolated_packages.py``) prune too.
2. ``colcon.pkg`` (JSON) may set the name and type and add dependencies, hooks and metadata.
3. ``package.xml`` makes a ROS package (``AMENT_IGNORE``/``CATKIN_IGNORE`` prune; a ROS 1 ``manifest.xml``
   without package.xml prunes too).
4. Otherwise ``CMakeLists.txt`` makes a ``cmake`` package (but not catkin_make's top-level file) and
   ``setup.py`` a ``python`` one; CMake wins over setup.py, but a directory that is CMake and also has a
   setup.cfg naming the project is ambiguous and pruned, as colcon does.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path

from roc.errors import ManifestError
from roc.messages import warn
from roc.workspace.cmake_project import read_cmake_project
from roc.workspace.manifest import parse_manifest
from roc.workspace.package import CATEGORIES, Package
from roc.workspace.python_setup import (
    PythonProject,
    read_setup_cfg,
    read_setup_py,
    setup_cfg_is_sufficient,
)

# Files of catkin devel/install spaces and ament_tools install spaces, which hold no markers.
INSTALL_SPACE_FILES = ("_setup_util.py", "_order_isolated_packages.py")


class SkipLocation(Exception):
    """This directory and everything below it is not to be crawled."""


def identify(directory: Path, shown_path: Path, filenames: set[str], variables: Mapping[str, str]) -> Package | None:
    """The package at ``directory`` (``filenames`` are its files), None if it is not one."""
    if "COLCON_IGNORE" in filenames or not filenames.isdisjoint(INSTALL_SPACE_FILES):
        raise SkipLocation
    config = _read_colcon_pkg(directory / "colcon.pkg") if "colcon.pkg" in filenames else {}
    wanted_type = config.get("type")
    package = None
    if wanted_type is None or wanted_type.startswith("ros."):
        package = _identify_ros(directory, shown_path, filenames, variables)
    if package is None and _reads_build_files(config):
        package = _identify_build_system(directory, shown_path, filenames, wanted_type)
    if package is None:
        if wanted_type and config.get("name"):
            package = Package(name=config["name"], path=shown_path, type=wanted_type)
        else:
            return None
    _apply_colcon_pkg(package, config)
    return package


def _reads_build_files(config: dict) -> bool:
    """Whether CMakeLists.txt and setup.py are looked at: not for ROS types, and not when colcon.pkg sets
    both the name and the type, which identifies the package by itself, so that colcon infers nothing
    from its CMakeLists.txt (a Python package's requirements are still read)."""
    wanted_type = config.get("type")
    if wanted_type is None:
        return True
    return not wanted_type.startswith("ros.") and (wanted_type == "python" or not config.get("name"))


def _identify_ros(directory: Path, shown_path: Path, filenames: set[str], variables) -> Package | None:
    if "AMENT_IGNORE" in filenames or "CATKIN_IGNORE" in filenames:
        raise SkipLocation
    if "package.xml" not in filenames:
        if "manifest.xml" in filenames:  # a ROS 1 dry package: not to be mistaken for a CMake one
            raise SkipLocation
        return None
    manifest = parse_manifest(directory / "package.xml", variables)
    if manifest.build_type == "ament_python" and "setup.py" not in filenames:
        warn(f"{shown_path}: ROS package '{manifest.name}' has build type ament_python but no setup.py; ignored")
        raise SkipLocation
    package = Package(name=manifest.name, path=shown_path, type=f"ros.{manifest.build_type}")
    for category, dependencies in manifest.category_dependencies().items():
        package.dependencies[category] = set(dependencies)
        for name, dependency in dependencies.items():
            if dependency.versions:
                package.constraints.setdefault(name, {}).update(dependency.versions)
    package.metadata["version"] = manifest.version
    maintainers = [m for m in manifest.maintainers if m.endswith(">")]
    if maintainers:
        package.metadata["maintainers"] = maintainers
    package.group_depends = manifest.group_depends
    package.member_of_groups = manifest.member_of_groups
    package.manifest = manifest
    return package


def _identify_build_system(directory: Path, shown_path: Path, filenames: set[str], wanted_type) -> Package | None:
    """colcon's precedence: CMakeLists.txt and a setup.cfg that names the project (next to a setup.py
    that calls a bare ``setup()``) identify at the same priority, so a directory with both is ambiguous;
    setup.py alone comes after CMake."""
    cmake = None
    if wanted_type in (None, "cmake") and "CMakeLists.txt" in filenames:
        cmake = _identify_cmake(directory, shown_path)
    if wanted_type not in (None, "python") or "setup.py" not in filenames:
        return cmake
    setup_py = directory / "setup.py"
    project = None
    if "setup.cfg" in filenames and setup_cfg_is_sufficient(setup_py):
        project = read_setup_cfg(directory / "setup.cfg")
    if cmake is not None:
        if project is not None:
            warn(f"{shown_path}: both a CMake and a Python package; ignored (add a colcon.pkg that sets its type)")
            raise SkipLocation
        return cmake
    return _python_package(project or read_setup_py(setup_py), shown_path)


def _identify_cmake(directory: Path, shown_path: Path) -> Package | None:
    project = read_cmake_project(directory / "CMakeLists.txt")
    if project is None:
        return None
    name, depends = project
    package = Package(name=name, path=shown_path, type="cmake")
    package.dependencies.update(build=set(depends), run=set(depends))
    return package


def _python_package(project: PythonProject, shown_path: Path) -> Package:
    package = Package(name=project.name, path=shown_path, type="python")
    for category in CATEGORIES:
        package.dependencies[category] = set(project.dependencies.get(category, ()))
    package.metadata["version"] = project.version  # None when unknown, as colcon shows it
    if project.maintainers:
        package.metadata["maintainers"] = project.maintainers
    return package


def _read_colcon_pkg(path: Path) -> dict:
    """The JSON object in colcon.pkg. colcon reads the file as YAML, a superset of JSON (trailing commas,
    comments, unquoted strings), so what strict JSON rejects is read as YAML too."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise ManifestError(str(path), f"cannot be read: {error.strerror or error}") from None
    if not text.strip():
        return {}
    try:
        data = json.loads(text)
    except json.JSONDecodeError as error:
        import yaml  # only for files that are not strict JSON

        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError:
            raise ManifestError(
                str(path), f"invalid JSON: {error.msg} at column {error.colno}; fix the syntax "
                "(colcon.pkg holds one JSON object such as {\"name\": \"my_pkg\", \"type\": \"cmake\"})",
                error.lineno,
            ) from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ManifestError(str(path), "must hold a JSON object such as {\"name\": \"my_pkg\", \"type\": \"cmake\"}")
    return data


def _apply_colcon_pkg(package: Package, config: dict) -> None:
    """Fold colcon.pkg into the package as colcon's ``update_descriptor`` does."""
    if "name" in config:  # colcon.pkg wins over the name the build system gives
        package.name = config["name"]
    for category in CATEGORIES:
        names = [*config.get("dependencies", ()), *config.get(f"{category}-dependencies", ())]
        if names:
            package.dependencies.setdefault(category, set()).update(names)
    package.hooks.extend(config.get("hooks", ()))
    reserved = {"name", "type", "dependencies", "hooks"} | {f"{c}-dependencies" for c in CATEGORIES}
    for key, value in config.items():
        if key not in reserved:
            package.metadata[key] = value
