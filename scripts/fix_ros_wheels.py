#!/usr/bin/env python3
"""Fix up installed ROS 2 PyPI wheels (Jazzy or Kilted) so that ament_cmake/rosidl builds work.

The wheels were built in a manylinux container and hard-code paths of that
container in some installed CMake files (see shared/ros2-wheels.md):

1. ``share/*/cmake/export_*__rosidl_generator_pyExport.cmake`` name the
   container's Python include directory and numpy include directory; CMake
   refuses imported targets with non-existent include paths.  They are
   rewritten to this interpreter's include directory and this environment's
   ``numpy.get_include()``.
2. Fast DDS's exported targets link ``/usr/lib64/libtinyxml2.so``, which
   does not exist here; the entry is removed (the library already needs the
   bundled tinyxml2). Jazzy's Fast DDS 2 has them in
   ``share/fastrtps/cmake/fastrtps-shared-targets.cmake``, Kilted's Fast DDS 3
   in ``share/fastdds/cmake/fastdds-shared-targets.cmake``.

Run it with the Python of the environment holding the wheels (it works on
``sys.prefix``, or on the prefix given with --prefix).  It is idempotent and
writes every changed file atomically.  This script is only for the
development/CI environment: roc itself never relies on it.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import sysconfig
import tempfile
from pathlib import Path

# Python include dir of the manylinux build container, e.g.
# /opt/python/cp311-cp311/include/python3.11
_PY_INCLUDE_RE = re.compile(r"/opt/python/cp\d+-cp\d+t?/include/python3\.\d+t?")
# numpy include dir inside that container (numpy 2: numpy/_core, numpy 1: numpy/core)
_NUMPY_INCLUDE_RE = re.compile(
    r"/opt/python/cp\d+-cp\d+t?/lib/python3\.\d+t?/site-packages/numpy/_?core/include"
)
_TINYXML2 = "/usr/lib64/libtinyxml2.so"
# Fast DDS's exported targets: Fast DDS 2 (Jazzy, libfastrtps), Fast DDS 3 (Kilted, libfastdds)
FASTDDS_TARGETS = ("fastrtps/cmake/fastrtps-shared-targets.cmake", "fastdds/cmake/fastdds-shared-targets.cmake")


def _write_atomic(path: Path, text: str) -> None:
    """Replace ``path`` with ``text`` atomically, keeping its permission bits."""
    mode = path.stat().st_mode & 0o7777
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
            f.write(text)
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def _read(path: Path) -> str:
    with open(path, encoding="utf-8", newline="") as f:
        return f.read()


def fix_rosidl_py_exports(text: str, py_include: str, numpy_include: str) -> str:
    # numpy first: its pattern is more specific than the Python include one.
    text = _NUMPY_INCLUDE_RE.sub(lambda _m: numpy_include, text)
    return _PY_INCLUDE_RE.sub(lambda _m: py_include, text)


def fix_fastdds_targets(text: str) -> str:
    """Drop the libtinyxml2 entry from the semicolon-separated link lists."""

    def fix_list(m: re.Match[str]) -> str:
        items = m.group(1).split(";")
        if _TINYXML2 not in items:
            return m.group(0)
        return '"' + ";".join(item for item in items if item != _TINYXML2) + '"'

    return re.sub(r'"([^"\n]*)"', fix_list, text)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--prefix",
        default=sys.prefix,
        help="install prefix holding share/ (default: this interpreter's sys.prefix)",
    )
    parser.add_argument(
        "--check", action="store_true", help="only report what would change; exit 1 if anything would"
    )
    parser.add_argument(
        "--quiet", action="store_true", help="print nothing unless a file was changed"
    )
    args = parser.parse_args(argv)
    prefix = Path(args.prefix)
    share = prefix / "share"

    py_include = sysconfig.get_paths()["include"]
    if not os.path.isfile(os.path.join(py_include, "Python.h")):
        print(f"fix_ros_wheels: error: no Python.h in {py_include}", file=sys.stderr)
        return 1
    try:
        import numpy  # noqa: PLC0415 - only needed here
    except ImportError:
        print("fix_ros_wheels: error: numpy is not installed in this environment", file=sys.stderr)
        return 1
    numpy_include = numpy.get_include()

    changes: list[tuple[Path, str]] = []
    exports = sorted(share.glob("*/cmake/export_*__rosidl_generator_pyExport.cmake"))
    for path in exports:
        old = _read(path)
        new = fix_rosidl_py_exports(old, py_include, numpy_include)
        if new != old:
            changes.append((path, new))

    fastdds = [share / name for name in FASTDDS_TARGETS if (share / name).is_file()]
    for path in fastdds:
        old = _read(path)
        new = fix_fastdds_targets(old)
        if new != old:
            changes.append((path, new))

    if not exports and not fastdds:
        print(f"fix_ros_wheels: warning: no ROS wheel CMake files found under {share}", file=sys.stderr)

    if args.check:
        for path, _ in changes:
            print(f"would fix {path}")
        print(f"fix_ros_wheels: {len(changes)} file(s) need fixing under {prefix}")
        return 1 if changes else 0

    for path, new in changes:
        _write_atomic(path, new)
    if args.quiet and not changes:
        return 0
    print(
        f"fix_ros_wheels: changed {len(changes)} file(s) under {prefix} "
        f"({len(exports)} rosidl_generator_py export file(s) checked, "
        f"Fast DDS targets {'checked' if fastdds else 'not found'})"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
