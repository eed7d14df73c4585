"""roc doctor's checks that builds can work (roc/doctor/build_tools.py, roc/doctor/wheel_defects.py): each
finds its defect in a made-up environment or prefix and names the command that repairs it, and passes
on the development venv (the ROS 2 wheels with what requirements/ros-jazzy.txt adds)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from roc import middleware
from roc.doctor import build_tools, wheel_defects


def _executable(path: Path, text: str = "#!/bin/sh\nexit 0\n") -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    path.chmod(0o755)
    return path


def test_build_tools_names_cmake_and_the_compiler_missing_from_path(tmp_path: Path) -> None:
    finding = build_tools.tools({"PATH": str(tmp_path)})
    assert finding.level == "warning"
    assert finding.message.startswith("cmake and a C++ compiler not found on PATH")
    assert finding.fix == "sudo apt install cmake g++ (Debian, Ubuntu)"
    _executable(tmp_path / "cmake"), _executable(tmp_path / "g++")
    assert (build_tools.tools({"PATH": str(tmp_path)}).level, build_tools.tools({"PATH": str(tmp_path)}).message) \
        == ("ok", "cmake, g++")
    assert build_tools.tools({"PATH": str(tmp_path), "CXX": "clang++-19"}).message.startswith(
        "a C++ compiler (clang++-19, from CXX) not found")


def test_the_python_cmake_finds_is_the_active_venvs_then_a_prefixs_then_paths(tmp_path: Path) -> None:
    venv, prefix, on_path = (_executable(tmp_path / name / "bin" / "python3") for name in ("venv", "prefix", "path"))
    env = {"PATH": str(on_path.parent), "AMENT_PREFIX_PATH": str(prefix.parent.parent)}
    assert build_tools.cmake_python(env) == prefix
    assert build_tools.cmake_python({**env, "VIRTUAL_ENV": str(venv.parent.parent)}) == venv
    assert build_tools.cmake_python({"PATH": str(on_path.parent)}) == on_path


def test_ament_python_names_the_python_that_cannot_import_ament_package_and_how_to_install_it(tmp_path: Path):
    # a venv's python3 that sees no site-packages: neither ament_package nor catkin_pkg imports
    venv = tmp_path / "venv"
    _executable(venv / "bin" / "python3", f'#!/bin/sh\nexec {sys.executable} -S "$@"\n')
    (venv / "pyvenv.cfg").write_text("home = /usr/bin\n")
    finding = build_tools.ament_python({"PATH": os.environ["PATH"], "VIRTUAL_ENV": str(venv)})
    assert finding.level == "error"
    assert finding.message == (f"{venv}/bin/python3, the Python ament_cmake's CMake finds, cannot import "
                               "ament_package and catkin_pkg: every ament_cmake package fails at configure")
    assert finding.fix == f"{venv}/bin/python3 -m pip install ros-jazzy-ament-package catkin-pkg"


def test_ament_python_outside_a_venv_says_to_source_ros_and_install_catkin_pkg(tmp_path: Path):
    python = _executable(tmp_path / "usr" / "bin" / "python3", f'#!/bin/sh\nexec {sys.executable} -S "$@"\n')
    assert build_tools.install_command(python, ["ament_package", "catkin_pkg"], {}) == (
        "source your ROS 2 setup script (/opt/ros/<distro>/setup.bash: its PYTHONPATH has ament_package); "
        "sudo apt install python3-catkin-pkg-modules")


def test_ament_python_passes_on_the_development_venv() -> None:
    finding = build_tools.ament_python(dict(os.environ))
    assert finding.level == "ok", finding


def _prefix(tmp_path: Path, packages: dict[str, list[str]]) -> Path:
    """A venv's prefix with ``packages`` installed, each naming its build tool exports in its package.xml."""
    index = tmp_path / "ros" / wheel_defects.AMENT_INDEX
    index.mkdir(parents=True)
    for name, exports in packages.items():
        (index / name).write_text("")
        (tmp_path / "ros" / "share" / name).mkdir(parents=True)
        (tmp_path / "ros" / "share" / name / "package.xml").write_text(
            f"<package format='3'><name>{name}</name>"
            + "".join(f"<buildtool_export_depend>{tool}</buildtool_export_depend>" for tool in exports)
            + "<buildtool_export_depend>python3-setuptools</buildtool_export_depend></package>")
    (tmp_path / "ros" / "pyvenv.cfg").write_text("home = /usr/bin\n")
    return tmp_path / "ros"


def test_wheel_packages_lists_what_the_meta_wheels_forgot_with_the_pip_command(tmp_path: Path) -> None:
    prefix = _prefix(tmp_path, {"ament_cmake_core": ["ament_package", "cmake"],
                                "ament_cmake_target_dependencies": ["ament_cmake_include_directories"],
                                "rosidl_default_generators": ["rosidl_core_generators"],
                                "rosidl_generator_py": ["python_cmake_module"], "python_cmake_module": []})
    finding = wheel_defects.missing_packages({"ROS_DISTRO": "jazzy"}, [prefix])
    assert finding.level == "error"
    assert finding.message.endswith(": ament_cmake_include_directories, ament_package, rosidl_core_generators")
    assert finding.fix == (f"{prefix}/bin/python -m pip install ros-jazzy-ament-cmake-include-directories "
                           "ros-jazzy-ament-package ros-jazzy-rosidl-core-generators")


def test_wheel_packages_asks_only_what_the_installed_packages_name(tmp_path: Path) -> None:
    # Kilted's rosidl_generator_py names no python_cmake_module; a rosdep key (python3-setuptools) is no package
    prefix = _prefix(tmp_path, {"ament_cmake_core": ["ament_package"], "ament_package": [],
                                "rosidl_generator_py": []})
    assert wheel_defects.missing_packages({"ROS_DISTRO": "kilted"}, [prefix]).level == "ok"


def test_wheel_packages_passes_on_the_development_venv() -> None:
    assert wheel_defects.missing_packages(dict(os.environ)).level == "ok"


def _librcl(tmp_path: Path, needed: list[str]) -> Path:
    """A stand-in librcl.so: the names of its dynamic section, as the linker writes them."""
    lib = tmp_path / "lib"
    lib.mkdir(parents=True, exist_ok=True)
    (lib / "librcl.so").write_bytes(b"\x7fELF\0" + b"\0".join(name.encode() for name in needed) + b"\0")
    return tmp_path


def test_rmw_implementation_naming_another_middleware_than_librcl_links_and_not_installed_is_an_error(
        tmp_path: Path) -> None:
    prefix = _librcl(tmp_path, ["librmw_fastrtps_cpp.so", "librmw.so", "librmw_fastrtps_shared_cpp.so",
                                "librmw_dds_common.so"])
    finding = wheel_defects.linked_rmw({"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}, [prefix])
    assert finding.level == "error"
    assert finding.message == (f"{prefix}/lib/librcl.so links rmw_fastrtps_cpp directly (the ROS 2 wheels do) and "
                               "RMW_IMPLEMENTATION=rmw_cyclonedds_cpp is not installed")
    assert finding.fix.endswith("or unset RMW_IMPLEMENTATION to use rmw_fastrtps_cpp")
    assert wheel_defects.linked_rmw({"RMW_IMPLEMENTATION": "rmw_fastrtps_cpp"}, [prefix]).level == "ok"
    assert wheel_defects.linked_rmw({}, [prefix]).level == "ok"


def test_another_installed_middleware_than_librcl_links_is_loaded_by_roc_and_preloaded_by_others(
        tmp_path: Path) -> None:
    prefix = _librcl(tmp_path, ["librmw_fastrtps_cpp.so", "librmw.so"])
    (prefix / "share/ament_index/resource_index/rmw_typesupport").mkdir(parents=True)
    (prefix / "share/ament_index/resource_index/rmw_typesupport/rmw_cyclonedds_cpp").write_text("")
    (prefix / "lib" / "librmw_cyclonedds_cpp.so").write_bytes(b"")
    finding = wheel_defects.linked_rmw({"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp", "AMENT_PREFIX_PATH": str(prefix)},
                                       [prefix])
    assert finding.level == "info"
    assert finding.message.endswith("roc loads rmw_cyclonedds_cpp first for itself and the nodes roc run and roc "
                                    f"launch start; other programs need LD_PRELOAD={prefix}/lib/librmw_cyclonedds_cpp.so")


def test_a_librcl_that_loads_the_middleware_at_run_time_lets_rmw_implementation_choose(tmp_path: Path) -> None:
    prefix = _librcl(tmp_path, ["librmw_implementation.so", "librmw.so", "librcutils.so"])
    finding = wheel_defects.linked_rmw({"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}, [prefix])
    assert (finding.level, finding.message) == ("ok", "librcl loads the middleware RMW_IMPLEMENTATION names")


def test_the_wheels_librcl_links_fast_dds() -> None:
    assert middleware.linked_middleware(Path(sys.prefix) / "lib" / "librcl.so") == "rmw_fastrtps_cpp"
