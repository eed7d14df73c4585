#!/usr/bin/env python3
"""Generate a synthetic, really buildable ROS 2 workspace for benchmarks.

    python bench/gen_workspace.py OUT_DIR --packages N [--seed S]

The mix of build types (exact counts, rounded):

* 50 % ``ros.ament_cmake``: a C++ static library (one .hpp/.cpp) exported with ``ament_export_targets``
  and ``ament_export_dependencies``; it ``find_package``s and links its dependencies and calls them.
  A small ``<name>_info`` executable links the library, so the whole link chain is exercised.
* 25 % ``ros.ament_python``: setup.py/setup.cfg/resource marker as ``ros2 pkg create`` writes them, a
  module and a console entry point; its dependencies (any type) are ``exec_depend``s, and the Python
  ones are imported.
* 15 % plain ``cmake`` without package.xml: a C++ library (and ``<name>_info`` executable) installing
  ``<name>Config.cmake`` and ``<name>Targets.cmake``; colcon infers its dependencies from its
  ``find_package`` calls.
* 10 % ``ros.cmake`` (package.xml with build type cmake): the same CMake project, dependencies declared
  in package.xml.

Packages are spread over about sqrt(N) layers; a package in layer L > 0 depends on 1-3 packages of
lower layers (one of them from layer L-1 when a suitable one exists), only on packages it can find:
CMake packages (ament or plain) on CMake packages, plain CMake ones only on plain CMake ones, Python
packages on anything. Everything is deterministic from ``--seed``.

Packages live in ``src/<repo>/<package>`` (a few packages per repository, with a README and a docs
directory that the crawl has to walk through). The tree is written to ``OUT_DIR.tmp`` and renamed into
place; an existing OUT_DIR is replaced only when it is a previous output of this generator.

Other scripts use ``generate(out, packages, seed)``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import shutil
import sys
from dataclasses import dataclass, field
from pathlib import Path

GENERATOR_VERSION = 2
MARKER = ".roc-bench-workspace"  # a file at the workspace root: what made it and with which parameters

AMENT_CMAKE = "ros.ament_cmake"
AMENT_PYTHON = "ros.ament_python"
CMAKE = "cmake"
ROS_CMAKE = "ros.cmake"
MIX = ((AMENT_CMAKE, 0.50), (AMENT_PYTHON, 0.25), (CMAKE, 0.15), (ROS_CMAKE, 0.10))

# Which build types a package of a given build type may depend on (and find at build time).
CAN_DEPEND_ON = {
    AMENT_CMAKE: {AMENT_CMAKE, CMAKE, ROS_CMAKE},
    CMAKE: {CMAKE, ROS_CMAKE},
    ROS_CMAKE: {CMAKE, ROS_CMAKE},
    AMENT_PYTHON: {AMENT_CMAKE, AMENT_PYTHON, CMAKE, ROS_CMAKE},
}

WORDS = (
    "arm", "base", "camera", "control", "costmap", "driver", "estimator", "filter", "fusion", "gazebo",
    "gps", "grid", "imu", "joint", "kinematics", "lidar", "localization", "map", "motion", "nav",
    "odometry", "path", "perception", "planner", "pose", "radar", "safety", "sensor", "slam", "teleop",
    "tracker", "trajectory", "utils", "vision", "wheel",
)
PACKAGES_PER_REPO = 8


@dataclass
class Spec:
    index: int
    name: str
    type: str
    layer: int
    repo: str
    depends: list[str] = field(default_factory=list)


def plan(packages: int, seed: int = 0) -> list[Spec]:
    """The packages of the workspace: names, build types, layers, repositories and dependencies."""
    if packages < 1:
        raise ValueError("--packages must be at least 1")
    rng = random.Random(seed)
    counts = [round(packages * share) for _, share in MIX]
    counts[0] += packages - sum(counts)  # rounding rest goes to ament_cmake
    types = [t for (t, _), n in zip(MIX, counts) for _ in range(n)]
    rng.shuffle(types)
    layers = max(1, round(math.sqrt(packages)))
    specs = []
    for i, build_type in enumerate(types):
        name = f"{rng.choice(WORDS)}_{rng.choice(WORDS)}_{i:04d}"
        specs.append(Spec(i, name, build_type, i * layers // packages, f"repo_{i // PACKAGES_PER_REPO:03d}"))
    by_layer: dict[int, list[Spec]] = {}
    for spec in specs:
        by_layer.setdefault(spec.layer, []).append(spec)
    for spec in specs:
        if spec.layer == 0:
            continue
        allowed = CAN_DEPEND_ON[spec.type]
        below = [s for s in specs if s.layer < spec.layer and s.type in allowed]
        if not below:
            continue
        wanted = min(rng.randint(1, 3), len(below))
        previous = [s for s in by_layer[spec.layer - 1] if s.type in allowed]
        chosen = [rng.choice(previous)] if previous else []
        rest = [s for s in below if s not in chosen]
        chosen += rng.sample(rest, wanted - len(chosen))
        spec.depends = sorted(s.name for s in chosen)
    return specs


# --------------------------------------------------------------------------------------------- files

def _package_xml(spec: Spec) -> str:
    if spec.type == AMENT_CMAKE:
        buildtool = "  <buildtool_depend>ament_cmake</buildtool_depend>\n"
        depends = "".join(f"  <depend>{d}</depend>\n" for d in spec.depends)
        build_type = "ament_cmake"
    elif spec.type == ROS_CMAKE:
        buildtool = "  <buildtool_depend>cmake</buildtool_depend>\n"
        depends = "".join(f"  <depend>{d}</depend>\n" for d in spec.depends)
        build_type = "cmake"
    else:
        buildtool = ""
        depends = "".join(f"  <exec_depend>{d}</exec_depend>\n" for d in spec.depends)
        build_type = "ament_python"
    return f"""<?xml version="1.0"?>
<?xml-model href="http://download.ros.org/schema/package_format3.xsd" schematypens="http://www.w3.org/2001/XMLSchema"?>
<package format="3">
  <name>{spec.name}</name>
  <version>0.1.{spec.index}</version>
  <description>Synthetic benchmark package {spec.name} (layer {spec.layer}).</description>
  <maintainer email="bench@example.com">Bench Maintainer</maintainer>
  <license>Apache-2.0</license>

{buildtool}{depends}
  <export>
    <build_type>{build_type}</build_type>
  </export>
</package>
"""


def _cpp_sources(spec: Spec) -> dict[str, str]:
    """Header and source of the package's library; it calls every dependency's ``value()``."""
    guard = f"{spec.name.upper()}__{spec.name.upper()}_HPP_"
    header = f"""#ifndef {guard}
#define {guard}

#include <string>

namespace {spec.name}
{{

/// A number that sums this package's own value with its dependencies' ones.
int value();

/// A description naming this package and its dependencies.
std::string describe();

}}  // namespace {spec.name}

#endif  // {guard}
"""
    includes = "".join(f'#include "{d}/{d}.hpp"\n' for d in spec.depends)
    value = " + ".join([str(spec.index + 1)] + [f"{d}::value()" for d in spec.depends])
    parts = "".join(f'  text += " " + {d}::describe();\n' for d in spec.depends)
    source = f"""#include "{spec.name}/{spec.name}.hpp"

#include <string>

{includes}
namespace {spec.name}
{{

int value()
{{
  return {value};
}}

std::string describe()
{{
  std::string text = "{spec.name}(";
{parts}  return text + ")";
}}

}}  // namespace {spec.name}
"""
    main = f"""#include <iostream>

#include "{spec.name}/{spec.name}.hpp"

int main()
{{
  std::cout << {spec.name}::describe() << " = " << {spec.name}::value() << std::endl;
  return 0;
}}
"""
    return {f"include/{spec.name}/{spec.name}.hpp": header, f"src/{spec.name}.cpp": source,
            "src/info_main.cpp": main}


def _ament_cmake_files(spec: Spec) -> dict[str, str]:
    finds = "".join(f"find_package({d} REQUIRED)\n" for d in spec.depends)
    links = "".join(f"\n  {d}::{d}" for d in spec.depends)
    link = f"target_link_libraries(${{PROJECT_NAME}} PUBLIC{links})\n" if spec.depends else ""
    exports = f"ament_export_dependencies({' '.join(spec.depends)})\n" if spec.depends else ""
    cmakelists = f"""cmake_minimum_required(VERSION 3.8)
project({spec.name} LANGUAGES CXX)

if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  add_compile_options(-Wall -Wextra -Wpedantic)
endif()

find_package(ament_cmake REQUIRED)
{finds}
add_library(${{PROJECT_NAME}} src/{spec.name}.cpp)
target_compile_features(${{PROJECT_NAME}} PUBLIC cxx_std_17)
set_target_properties(${{PROJECT_NAME}} PROPERTIES POSITION_INDEPENDENT_CODE ON)
target_include_directories(${{PROJECT_NAME}} PUBLIC
  "$<BUILD_INTERFACE:${{CMAKE_CURRENT_SOURCE_DIR}}/include>"
  "$<INSTALL_INTERFACE:include/${{PROJECT_NAME}}>")
{link}
# An executable, so that linking against the whole dependency chain is exercised.
add_executable(${{PROJECT_NAME}}_info src/info_main.cpp)
target_link_libraries(${{PROJECT_NAME}}_info PRIVATE ${{PROJECT_NAME}})

install(DIRECTORY include/ DESTINATION include/${{PROJECT_NAME}})
install(TARGETS ${{PROJECT_NAME}}
  EXPORT export_${{PROJECT_NAME}}
  ARCHIVE DESTINATION lib
  LIBRARY DESTINATION lib
  RUNTIME DESTINATION bin)
install(TARGETS ${{PROJECT_NAME}}_info DESTINATION lib/${{PROJECT_NAME}})

ament_export_targets(export_${{PROJECT_NAME}} HAS_LIBRARY_TARGET)
{exports}ament_package()
"""
    return {"CMakeLists.txt": cmakelists, **_cpp_sources(spec)}


def _plain_cmake_files(spec: Spec) -> dict[str, str]:
    finds = "".join(f"find_package({d} REQUIRED)\n" for d in spec.depends)
    links = "".join(f"\n  {d}::{d}" for d in spec.depends)
    link = f"target_link_libraries({spec.name} PUBLIC{links})\n" if spec.depends else ""
    cmakelists = f"""cmake_minimum_required(VERSION 3.14)
project({spec.name} VERSION 0.1.{spec.index} LANGUAGES CXX)

{finds}
add_library({spec.name} src/{spec.name}.cpp)
add_library({spec.name}::{spec.name} ALIAS {spec.name})
target_compile_features({spec.name} PUBLIC cxx_std_17)
set_target_properties({spec.name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
target_include_directories({spec.name} PUBLIC
  "$<BUILD_INTERFACE:${{CMAKE_CURRENT_SOURCE_DIR}}/include>"
  "$<INSTALL_INTERFACE:include>")
{link}
# An executable, so that linking against the whole dependency chain is exercised.
add_executable({spec.name}_info src/info_main.cpp)
target_link_libraries({spec.name}_info PRIVATE {spec.name})

install(DIRECTORY include/ DESTINATION include)
install(TARGETS {spec.name}
  EXPORT {spec.name}Targets
  ARCHIVE DESTINATION lib
  LIBRARY DESTINATION lib
  RUNTIME DESTINATION bin)
install(TARGETS {spec.name}_info DESTINATION bin)
install(EXPORT {spec.name}Targets NAMESPACE {spec.name}:: DESTINATION lib/cmake/{spec.name})
install(FILES cmake/{spec.name}Config.cmake DESTINATION lib/cmake/{spec.name})
"""
    # find_dependency (not find_package) so that colcon's CMake scan sees only the CMakeLists.txt calls.
    deps = "".join(f"find_dependency({d})\n" for d in spec.depends)
    config = f"""# Config file of {spec.name}: its dependencies, then its exported targets.
include(CMakeFindDependencyMacro)
{deps}include("${{CMAKE_CURRENT_LIST_DIR}}/{spec.name}Targets.cmake")
"""
    return {"CMakeLists.txt": cmakelists, f"cmake/{spec.name}Config.cmake": config,
            **_cpp_sources(spec)}


def _ament_python_files(spec: Spec, by_name: dict[str, Spec]) -> dict[str, str]:
    name = spec.name
    setup_py = f"""from setuptools import find_packages, setup

package_name = '{name}'

setup(
    name=package_name,
    version='0.1.{spec.index}',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages',
            ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Bench Maintainer',
    maintainer_email='bench@example.com',
    description='Synthetic benchmark package {name} (layer {spec.layer}).',
    license='Apache-2.0',
    entry_points={{
        'console_scripts': [
            '{name}_main = {name}.main:main',
        ],
    }},
)
"""
    setup_cfg = f"""[develop]
script_dir=$base/lib/{name}
[install]
install_scripts=$base/lib/{name}
"""
    python_deps = [d for d in spec.depends if by_name[d].type == AMENT_PYTHON]
    imports = "".join(f"import {d}.main\n" for d in python_deps)
    values = " + ".join([str(spec.index + 1)] + [f"{d}.main.value()" for d in python_deps])
    others = [d for d in spec.depends if d not in python_deps]
    main_py = f'''"""Entry point of {name}."""

{imports}
USES = {others!r}  # non-Python run dependencies


def value():
    return {values}


def main():
    print(f"{name}: value={{value()}} uses={{USES}}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
'''
    return {
        "setup.py": setup_py,
        "setup.cfg": setup_cfg,
        f"resource/{name}": "",
        f"{name}/__init__.py": "",
        f"{name}/main.py": main_py,
    }


def package_files(spec: Spec, by_name: dict[str, Spec]) -> dict[str, str]:
    """Relative path -> content of every file of the package."""
    if spec.type == AMENT_CMAKE:
        files = _ament_cmake_files(spec)
    elif spec.type == AMENT_PYTHON:
        files = _ament_python_files(spec, by_name)
    else:
        files = _plain_cmake_files(spec)
    if spec.type != CMAKE:
        files["package.xml"] = _package_xml(spec)
    return files


# ------------------------------------------------------------------------------------------ writing

def _write(base: Path, files: dict[str, str]) -> None:
    for relative, content in files.items():
        path = base / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(content, encoding="utf-8")


def generate(out: Path, packages: int, seed: int = 0) -> None:
    """Write a workspace of ``packages`` packages to ``out`` (replacing a previous generated one)."""
    out = Path(out)
    if out.exists() and not (out / MARKER).is_file():
        raise FileExistsError(f"{out} exists and was not made by gen_workspace.py; not replacing it")
    specs = plan(packages, seed)
    by_name = {s.name: s for s in specs}
    tmp = out.with_name(out.name + ".tmp")
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir(parents=True)
    repos: dict[str, list[Spec]] = {}
    for spec in specs:
        repos.setdefault(spec.repo, []).append(spec)
    for repo, members in repos.items():
        repo_dir = tmp / "src" / repo
        listing = "".join(f"- {s.name} ({s.type})\n" for s in members)
        _write(repo_dir, {
            "README.md": f"# {repo}\n\nSynthetic repository:\n\n{listing}",
            "docs/index.md": f"# {repo} documentation\n",
            ".git-placeholder/HEAD": "ref: refs/heads/main\n",  # hidden: skipped by the crawl
        })
        for spec in members:
            _write(repo_dir / spec.name, package_files(spec, by_name))
    counts = {t: sum(1 for s in specs if s.type == t) for t, _ in MIX}
    (tmp / MARKER).write_text(json.dumps({
        "generator_version": GENERATOR_VERSION, "packages": packages, "seed": seed, "types": counts,
        "layers": max(s.layer for s in specs) + 1,
    }, indent=2) + "\n")
    old = out.with_name(out.name + ".old")
    if old.exists():
        shutil.rmtree(old)
    if out.exists():
        os.rename(out, old)
    os.rename(tmp, out)
    if old.exists():
        shutil.rmtree(old)


def read_marker(out: Path) -> dict | None:
    """The parameters a generated workspace was made with, None if ``out`` is not one."""
    try:
        return json.loads((Path(out) / MARKER).read_text())
    except (OSError, ValueError):
        return None


def ensure(out: Path, packages: int, seed: int = 0) -> bool:
    """Generate ``out`` unless it already holds this very workspace; True when it was (re)generated."""
    marker = read_marker(out)
    if marker and (marker.get("generator_version"), marker.get("packages"), marker.get("seed")) == (
            GENERATOR_VERSION, packages, seed):
        return False
    generate(out, packages, seed)
    return True


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, help="workspace directory to create (or replace)")
    parser.add_argument("--packages", "-n", type=int, required=True, help="number of packages")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    args = parser.parse_args(argv)
    try:
        generate(args.out, args.packages, args.seed)
    except (ValueError, FileExistsError) as error:
        print(f"gen_workspace.py: error: {error}", file=sys.stderr)
        return 2
    marker = read_marker(args.out)
    print(f"generated {args.packages} packages in {marker['layers']} layers at {args.out}: "
          + ", ".join(f"{n} {t}" for t, n in marker["types"].items()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
