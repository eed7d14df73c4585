"""The guard every roc process puts before rclpy's import. A module of its own, importing nothing at
start: every command installs it, and most never load rclpy (roc.distribution's dataclasses would cost
each of them some 8 ms)."""

from __future__ import annotations

import sys
from collections.abc import Sequence


class _RclpyImportGuard:
    """A finder first on ``sys.meta_path`` that lets rclpy be imported only once
    ``roc.distribution.refuse_mix`` passed, and after the middleware RMW_IMPLEMENTATION names is loaded
    where librcl would load another (roc.middleware.load_chosen): it sees every import of rclpy, whichever
    module asks (the graph, bags, the bridge, the TUI, launch)."""

    def find_spec(self, name: str, path: Sequence[str] | None = None, target: object = None) -> None:
        if name == "rclpy":
            from roc.distribution import refuse_mix
            from roc.middleware import load_chosen

            refuse_mix()  # raises before any of rclpy's libraries is loaded
            load_chosen()
            sys.meta_path.remove(self)
        return None  # the ordinary finders find it


def guard_rclpy_import() -> None:
    """Refuse, as a one-line error, every import of rclpy in this process while two distributions are
    sourced; without it, one's rclpy loaded on the other's libraries fails in C (rcutils errors,
    std::bad_array_new_length) and the process dies of a segmentation fault."""
    if "rclpy" not in sys.modules and not any(isinstance(f, _RclpyImportGuard) for f in sys.meta_path):
        sys.meta_path.insert(0, _RclpyImportGuard())
