#!/usr/bin/env python3
"""Repair installed ROS 2 PyPI wheels (Jazzy or Kilted) so that ament_cmake builds and C++ programs work:
the repairs of ``roc doctor --fix`` (roc/doctor/wheel_repairs.py says what each one mends), run by
roc's development set-up.

Run it with the Python of the environment holding the wheels (it works on ``sys.prefix``, or on the
prefix given with --prefix). It is idempotent and writes every changed file atomically.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

# roc from this checkout, also for a venv that has the wheels but not roc (the tests' ros2 CLI oracle)
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from roc.doctor import wheel_repairs  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--prefix", default=sys.prefix,
                        help="install prefix holding share/ (default: this interpreter's sys.prefix)")
    parser.add_argument("--check", action="store_true", help="only report what would change; exit 1 if anything would")
    parser.add_argument("--quiet", action="store_true", help="print nothing unless a file was changed")
    args = parser.parse_args(argv)
    prefix = Path(args.prefix)

    python = wheel_repairs.this_interpreter()
    if not os.path.isfile(os.path.join(python.include, "Python.h")):
        print(f"fix_ros_wheels: error: no Python.h in {python.include}", file=sys.stderr)
        return 1
    if python.numpy_include is None:
        print("fix_ros_wheels: error: numpy is not installed in this environment", file=sys.stderr)
        return 1
    repairs = wheel_repairs.planned(prefix, python)
    if args.check:
        for repair in repairs:
            print(f"would fix {repair.path}: {repair.why}")
        print(f"fix_ros_wheels: {len(repairs)} file(s) need fixing under {prefix}")
        return 1 if repairs else 0
    wheel_repairs.apply(repairs)
    if repairs or not args.quiet:
        print(f"fix_ros_wheels: changed {len(repairs)} file(s) under {prefix}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
