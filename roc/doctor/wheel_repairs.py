"""Repairs of ROS 2 installed from PyPI wheels (Jazzy, Kilted), without which ament_cmake builds or C++
programs fail. ``roc doctor`` reports what is needed and ``roc doctor --fix`` applies it;
``scripts/fix_ros_wheels.py`` runs the same for roc's development set-up.

The wheels were built in a manylinux container, which leaves these defects in the installed files:

1. ``share/*/cmake/export_*__rosidl_generator_pyExport.cmake`` name the container's Python and numpy
   include directories: CMake refuses the imported targets ("includes non-existent path"), and every
   interface package depending on std_msgs & co fails. They are pointed at this interpreter's.
2. The same rosidl_generator_py libraries use CPython's API without linking libpython (manylinux
   forbids it), and librcl links them: every C++ program linking rcl (rclcpp) fails with
   ``undefined reference to '_Py_Dealloc'``. Their exported targets get libpython in their link
   interface, as an apt install of ROS links it.
3. Fast DDS's exported targets link ``/usr/lib64/libtinyxml2.so``, which does not exist here: the entry
   is dropped (libfastrtps/libfastdds already carries its bundled tinyxml2).
4. tracetools' exported targets ask for ``-llttng-ust``, which the wheel ships only under a renamed file
   in ``ros_tracetools.libs``: every package linking tracetools (rclcpp, every RMW) fails with ``cannot
   find -llttng-ust``. The entry is dropped (libtracetools already needs the renamed library).

Every repair is idempotent and written atomically.
"""

from __future__ import annotations

import os
import re
import sysconfig
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from roc.fsutil import write_text_atomic

# Python include dir of the manylinux build container, e.g. /opt/python/cp311-cp311/include/python3.11
_PY_INCLUDE_RE = re.compile(r"/opt/python/cp\d+-cp\d+t?/include/python3\.\d+t?")
# numpy include dir inside that container (numpy 2: numpy/_core, numpy 1: numpy/core)
_NUMPY_INCLUDE_RE = re.compile(r"/opt/python/cp\d+-cp\d+t?/lib/python3\.\d+t?/site-packages/numpy/_?core/include")
_TINYXML2 = "/usr/lib64/libtinyxml2.so"
# Fast DDS's exported targets: Fast DDS 2 (Jazzy, libfastrtps), Fast DDS 3 (Kilted, libfastdds)
FASTDDS_TARGETS = ("fastrtps/cmake/fastrtps-shared-targets.cmake", "fastdds/cmake/fastdds-shared-targets.cmake")
TRACETOOLS_EXPORTS = ("tracetools/cmake/ament_cmake_export_libraries-extras.cmake",
                      "tracetools/cmake/tracetools_exportExport.cmake")
_LTTNG = "lttng-ust"


@dataclass(frozen=True)
class Interpreter:
    """What the repairs take from the Python that ament_cmake builds with."""

    include: str  # the directory of Python.h
    numpy_include: str | None
    libpython: str | None  # the shared libpython to link C++ programs with, None when there is none


@dataclass(frozen=True)
class Repair:
    path: Path
    text: str  # the file's repaired text
    why: str  # one line: what was wrong


def this_interpreter() -> Interpreter:
    try:
        import numpy  # noqa: PLC0415 - only the rosidl_generator_py repair needs it
        numpy_include: str | None = numpy.get_include()
    except ImportError:
        numpy_include = None
    return Interpreter(sysconfig.get_paths()["include"], numpy_include, shared_libpython())


def shared_libpython() -> str | None:
    """The path of this interpreter's shared libpython (``libpython3.X.so``), None when there is none
    (a static build without python3.X-dev's shared library)."""
    name = f"libpython{sysconfig.get_config_var('LDVERSION') or sysconfig.get_python_version()}.so"
    folders = [sysconfig.get_config_var("LIBDIR"), sysconfig.get_config_var("LIBPL")]
    multiarch = sysconfig.get_config_var("MULTIARCH")
    if multiarch:
        folders.append(f"/usr/lib/{multiarch}")
    for folder in folders:
        if folder and os.path.exists(os.path.join(folder, name)):
            return os.path.join(folder, name)
    return None


def _quoted_lists(text: str, edit: Callable[[list[str]], list[str]]) -> str:
    """``text`` with each "a;b;c" list (a quoted string holding a semicolon-separated list) edited."""

    def one(match: re.Match[str]) -> str:
        items = match.group(1).split(";")
        edited = edit(items)
        return match.group(0) if edited == items else '"' + ";".join(edited) + '"'

    return re.sub(r'"([^"\n]*)"', one, text)


def repair_rosidl_py_export(text: str, python: Interpreter) -> str:
    if python.numpy_include:  # numpy first: its pattern is more specific than the Python include one
        text = _NUMPY_INCLUDE_RE.sub(lambda _m: python.numpy_include or "", text)
    text = _PY_INCLUDE_RE.sub(lambda _m: python.include, text)
    if python.libpython:
        # The library's own dependency on libpython, after it on every link line that has it. Linked
        # whatever --as-needed says (Debian's and Ubuntu's default): the program itself uses no CPython
        # symbol, and ld then drops libpython and fails on the library's undefined ones.
        wanted = f'  INTERFACE_LINK_LIBRARIES "-Wl,--no-as-needed;{python.libpython};-Wl,--as-needed"'
        if "INTERFACE_LINK_LIBRARIES" in text:  # the wheels list none here: a line of an earlier repair
            text = re.sub(r"^  INTERFACE_LINK_LIBRARIES .*$", lambda _m: wanted, text, count=1, flags=re.MULTILINE)
        else:
            text = re.sub(r"^(  INTERFACE_INCLUDE_DIRECTORIES .*)$", lambda m: f"{m.group(1)}\n{wanted}",
                          text, count=1, flags=re.MULTILINE)
    return text


def repair_fastdds_targets(text: str) -> str:
    return _quoted_lists(text, lambda items: [item for item in items if item != _TINYXML2])


def repair_tracetools_exports(text: str) -> str:
    return _quoted_lists(text, lambda items: [item for item in items if item != _LTTNG])


def _read(path: Path) -> str:
    with open(path, encoding="utf-8", newline="") as f:
        return f.read()


def planned(prefix: Path, python: Interpreter) -> list[Repair]:
    """The repairs the wheels installed in ``prefix`` need (none for an apt install of ROS)."""
    share = prefix / "share"
    candidates: list[tuple[Path, Callable[[str], str], str]] = []
    for path in sorted(share.glob("*/cmake/export_*__rosidl_generator_pyExport.cmake")):
        candidates.append((path, lambda text: repair_rosidl_py_export(text, python),
                           "names the wheel builder's Python include directories, or links no libpython"))
    for name in FASTDDS_TARGETS:
        candidates.append((share / name, repair_fastdds_targets, f"links {_TINYXML2}, which does not exist"))
    if not (prefix / "lib" / "liblttng-ust.so").exists():
        for name in TRACETOOLS_EXPORTS:
            candidates.append((share / name, repair_tracetools_exports,
                               "links lttng-ust, which the wheel ships only under another name"))
    repairs = []
    for path, repair, why in candidates:
        if path.is_file():
            old = _read(path)
            new = repair(old)
            if new != old:
                repairs.append(Repair(path, new, why))
    return repairs


def apply(repairs: list[Repair]) -> None:
    for repair in repairs:
        write_text_atomic(repair.path, repair.text)
