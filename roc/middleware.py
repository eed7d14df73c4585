"""What differs between ROS 2 middlewares (RMW implementations) for a process, as roc/distribution.py holds
what differs between distributions: which middleware a process gets.

A ROS 2 from apt or source loads the middleware RMW_IMPLEMENTATION names itself (through
librmw_implementation). The ROS 2 wheels' librcl instead links librmw_fastrtps_cpp directly, so
RMW_IMPLEMENTATION alone cannot choose another: rcl then exits 102 ("Expected RMW implementation identifier
of 'rmw_cyclonedds_cpp' but instead found 'rmw_fastrtps_cpp'"). Loading the chosen middleware's library
first, into the global symbol scope, binds rcl's rmw calls to it. roc does that only where it is needed
(RMW_IMPLEMENTATION names another middleware than the one librcl links): in its own processes with ctypes
before rclpy is imported (``load_chosen``, called by roc.distribution's rclpy import guard), and for the
processes it starts (the daemon, the nodes of roc run and roc launch) with LD_PRELOAD in their environment
(``process_environment``). Plain files and ctypes only: no rclpy."""

from __future__ import annotations

import ctypes
import functools
import os
import re
from collections.abc import Mapping
from pathlib import Path

from roc.environment import ament_prefixes
from roc.errors import RocError

DEFAULT = "rmw_fastrtps_cpp"  # what rcl loads when RMW_IMPLEMENTATION is not set
# the ament index's resource of every middleware (the one rmw_implementation registers is no middleware)
RESOURCE = Path("share", "ament_index", "resource_index", "rmw_typesupport")
# a middleware's library named in librcl's dynamic section: librcl then loads it, not RMW_IMPLEMENTATION's
_RMW_LIBRARY = re.compile(rb"\0lib(rmw_(?!implementation\b|dds_common\b)[a-z0-9_]+?)\.so\0")
_NOT_MIDDLEWARES = ("_shared_cpp", "_shared_c")


class MiddlewareNotLoadable(RocError):
    """RMW_IMPLEMENTATION names a middleware that is not installed, or whose library does not load."""


def chosen(environ: Mapping[str, str]) -> str:
    """The middleware RMW_IMPLEMENTATION names (Fast DDS, rcl's default, when it is not set)."""
    return environ.get("RMW_IMPLEMENTATION") or DEFAULT


def linked_middleware(librcl: Path) -> str | None:
    """The middleware librcl links directly (the ROS 2 wheels' librcl links rmw_fastrtps_cpp), None when it
    loads the one RMW_IMPLEMENTATION names (through rmw_implementation), as a source or apt build does."""
    try:
        data = librcl.read_bytes()
    except OSError:
        return None
    for match in _RMW_LIBRARY.finditer(data):
        name = match.group(1).decode()
        if not name.endswith(_NOT_MIDDLEWARES):
            return name
    return None


def rcl_library(environ: Mapping[str, str]) -> Path | None:
    """The librcl of the first ament prefix that has one (the one rclpy loads), None when none has."""
    for prefix in ament_prefixes(environ):
        if (prefix / "lib" / "librcl.so").is_file():
            return prefix / "lib" / "librcl.so"
    return None


def installed(environ: Mapping[str, str]) -> dict[str, Path]:
    """Every middleware of the ament index and the library that is it (lib/lib<name>.so of its prefix)."""
    found: dict[str, Path] = {}
    for prefix in ament_prefixes(environ):
        try:
            names = os.listdir(prefix / RESOURCE)
        except OSError:
            continue
        for name in names:
            if not name.startswith(".") and name != "rmw_implementation":
                found.setdefault(name, prefix / "lib" / f"lib{name}.so")
    return found


def library_to_load(environ: Mapping[str, str]) -> Path | None:
    """The library of the middleware RMW_IMPLEMENTATION names when it must be loaded before librcl: the
    middleware is not the one librcl links directly. None when rcl gets it on its own."""
    name = environ.get("RMW_IMPLEMENTATION")
    librcl = rcl_library(environ) if name else None
    linked = linked_middleware(librcl) if librcl is not None else None
    if name is None or linked is None or linked == name:
        return None
    library = installed(environ).get(name)
    if library is None or not library.is_file():
        raise MiddlewareNotLoadable(
            f"RMW_IMPLEMENTATION={name}: no such middleware is installed in the ament index (AMENT_PREFIX_PATH): "
            f"source the setup script of the workspace that built it, or unset RMW_IMPLEMENTATION to use {linked}")
    return library


@functools.cache
def _load(library: Path, name: str, scope: int) -> None:
    """Load ``library``: into the global symbol scope (os.RTLD_GLOBAL), where librcl's rmw calls bind to
    it, or only to check that it loads (os.RTLD_LOCAL: this process's own middleware stays the same)."""
    try:
        ctypes.CDLL(str(library), mode=os.RTLD_NOW | scope)
    except OSError as error:
        raise MiddlewareNotLoadable(f"RMW_IMPLEMENTATION={name}: {library} does not load ({error}): install what "
                                    "it needs (ldd shows what is missing) or unset RMW_IMPLEMENTATION") from None


def load_chosen(environ: Mapping[str, str] | None = None) -> None:
    """Load RMW_IMPLEMENTATION's middleware into this process where librcl would load another: call it
    before rclpy is imported. Raises MiddlewareNotLoadable (one line, with the fix) when it cannot."""
    environ = os.environ if environ is None else environ
    library = library_to_load(environ)
    if library is not None:
        _load(library, chosen(environ), os.RTLD_GLOBAL)


def process_environment(env: Mapping[str, str]) -> dict[str, str]:
    """``env`` for a process roc starts (the daemon, a node): with RMW_IMPLEMENTATION's middleware in
    LD_PRELOAD where librcl would load another, after checking here that it loads."""
    library = library_to_load(env)
    if library is None:
        return dict(env)
    _load(library, chosen(env), os.RTLD_LOCAL)
    preloaded = env.get("LD_PRELOAD", "").replace(":", " ").split()
    if str(library) in preloaded:
        return dict(env)
    return {**env, "LD_PRELOAD": " ".join([str(library), *preloaded])}
