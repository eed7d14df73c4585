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
            load_type_support_importer()
            sys.meta_path.remove(self)
        return None  # the ordinary finders find it


def load_type_support_importer() -> None:
    """Load ``rosidl_generator_py`` without its code generator, which it loads again when asked for it.
    Every message's first use imports its type support through ``rosidl_generator_py.import_type_support``,
    and the package's ``__init__`` also imports ``generate_py`` (rosidl_parser, lark): 50 ms of every
    process's first message, the first query of each graph verb included, for a generator no roc
    process runs. Upstream's ``__init__`` already treats the generator as optional."""
    if "rosidl_generator_py" in sys.modules:
        return
    import importlib.util

    spec = importlib.util.find_spec("rosidl_generator_py")
    if spec is None or spec.submodule_search_locations is None:
        return
    package = importlib.util.module_from_spec(spec)  # its __init__ is not run
    sys.modules[spec.name] = package
    try:
        from rosidl_generator_py.import_type_support_impl import import_type_support
    except ImportError:
        del sys.modules[spec.name]
        return
    package.import_type_support = import_type_support  # type: ignore[attr-defined]
    package.__all__ = ["import_type_support", "generate_py"]  # type: ignore[attr-defined]
    package.__getattr__ = _generator  # type: ignore[method-assign]


def _generator(name: str) -> object:
    """``rosidl_generator_py.generate_py``, imported when first asked for (PEP 562)."""
    if name == "generate_py":
        from rosidl_generator_py.generate_py_impl import generate_py

        return generate_py
    raise AttributeError(f"module 'rosidl_generator_py' has no attribute {name!r}")


def guard_rclpy_import() -> None:
    """Refuse, as a one-line error, every import of rclpy in this process while two distributions are
    sourced; without it, one's rclpy loaded on the other's libraries fails in C (rcutils errors,
    std::bad_array_new_length) and the process dies of a segmentation fault."""
    if "rclpy" not in sys.modules and not any(isinstance(f, _RclpyImportGuard) for f in sys.meta_path):
        sys.meta_path.insert(0, _RclpyImportGuard())
