"""Build types: how each kind of package (ament_cmake, cmake, ament_python, python) is built.

``BUILD_TYPES`` is the registry: a package type (as discovery names it) to the function that builds
it, ``module:function``, imported only when a package of that type is built. A new build type is a
module here with a ``(TaskContext, PackageJob, BuildOptions) -> None`` function and one entry below.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable

BUILD_TYPES: dict[str, str] = {
    "ros.ament_cmake": "roc.buildtypes.cmake:build_cmake",
    "ros.cmake": "roc.buildtypes.cmake:build_cmake",
    "cmake": "roc.buildtypes.cmake:build_cmake",
    "ros.ament_python": "roc.buildtypes.python:build_python",
    "python": "roc.buildtypes.python:build_python",
}


def build_function(package_type: str) -> Callable:
    module, function = BUILD_TYPES[package_type].split(":")
    return getattr(importlib.import_module(module), function)
