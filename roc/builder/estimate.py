"""A guess at how long a package takes to build, for the scheduler's critical path before roc has recorded a
duration for it (roc.engine.store): on a fresh machine, too, the longest chain starts first.

It counts what costs build time: each compiled source and each interface definition (whose code is
generated and compiled for every language), about 4 s each on one core. The C++ stack's packages took 2 to
14 s a source (rclcpp 2.3 s, demo_nodes_cpp 11.5 s) and 4 to 8 s an interface definition
(example_interfaces 3.8 s). Only the order matters: the duration recorded by the first build replaces it.
"""

from __future__ import annotations

import os
from pathlib import Path

from roc.builder.state import STATE_FILE

COMPILED = frozenset((".c", ".cc", ".cpp", ".cxx", ".c++"))
INTERFACES = frozenset((".msg", ".srv", ".action", ".idl", ".proto"))
SECONDS_EACH = 4.0
COUNTED = COMPILED | INTERFACES
AT_LEAST = 1.0  # a package with neither (Python, CMake files alone): the weight of any unknown task


def estimated_seconds(source: Path) -> float:
    counted = 0
    for _, directories, files in os.walk(source):
        directories[:] = [d for d in directories if not d.startswith(".")]
        counted += sum(1 for name in files if os.path.splitext(name)[1] in COUNTED)
    return max(AT_LEAST, SECONDS_EACH * counted)


def package_weight(recorded: float | None, source: Path, build_dir: Path) -> float:
    """The scheduler's weight of a package's build: its ``recorded`` duration; the estimate when it was never
    built here. One restored from a cache has a state but no duration: estimating it would walk its sources
    on every no-op build, so it weighs as any unknown task."""
    if recorded is not None:
        return recorded
    if (build_dir / STATE_FILE).exists():
        return AT_LEAST
    return estimated_seconds(source)
