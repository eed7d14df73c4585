"""Where each package builds and installs, and the markers colcon leaves in the bases."""

from __future__ import annotations

import os
from pathlib import Path

from roc.errors import RocError, UsageError
from roc.fsutil import write_text_atomic
from roc.workspace.dependencies import layered_order

LAYOUT_MARKER = ".colcon_install_layout"
BUILT_BY_MARKER = ".built_by"
# roc's build directories follow colcon's layout, so colcon may build in them and the other way round.
COMPATIBLE_BUILD_TOOLS = ("colcon", "roc")


def package_prefix(install_base: Path, name: str, merged: bool) -> Path:
    return install_base if merged else install_base / name


def prepare_build_base(build_base: Path) -> None:
    marker = build_base / BUILT_BY_MARKER
    if marker.is_file():
        tool = marker.read_text().strip()
        if tool not in COMPATIBLE_BUILD_TOOLS:
            raise RocError(f"the build directory '{build_base}' was made by '{tool}'; "
                           "remove it or choose another with --build-base")
    else:
        if build_base.exists() and not build_base.is_dir():
            raise UsageError(f"--build-base '{build_base}' is not a directory")
        write_text_atomic(marker, "colcon\n")
    if not (build_base / "COLCON_IGNORE").exists():
        write_text_atomic(build_base / "COLCON_IGNORE", "")


def check_distribution(build_base: Path, install_base: Path) -> None:
    """Refuse, before anything is written, to build in an environment that sources two ROS 2
    distributions, or with another distribution than the one the build base was built with (its CMake
    caches and the install point at that one's files)."""
    from roc import distribution

    distribution.refuse_mix()
    found = distribution.detected()
    built = distribution.built_with(build_base)
    if found is not None and built and built != found[0]:
        name, where = found
        raise RocError(f"'{build_base}' was built with ROS 2 {built}, but the sourced ROS 2 is {name} ({where}): "
                       f"source {built}, or remove '{build_base}' and '{install_base}' to build with {name}")


def record_distribution(build_base: Path) -> None:
    """Write the distribution the build base is built with (roc.distribution.MARKER)."""
    from roc import distribution

    found = distribution.detected()
    if found is not None and distribution.built_with(build_base) != found[0]:
        write_text_atomic(build_base / distribution.MARKER, found[0] + "\n")


def prepare_install_base(install_base: Path, merged: bool) -> None:
    """Refuse to mix isolated and merged layouts in one install base."""
    layout = "merged" if merged else "isolated"
    marker = install_base / LAYOUT_MARKER
    if marker.is_file():
        previous = marker.read_text().strip()
        if previous != layout:
            change = "remove" if merged else "add"
            raise UsageError(
                f"the install base '{install_base}' has the {previous} layout; remove it, choose another "
                f"--install-base, or {change} --merge-install"
            )
    else:
        if install_base.exists() and not install_base.is_dir():
            raise UsageError(f"--install-base '{install_base}' is not a directory")
        write_text_atomic(marker, layout + "\n")
    if not (install_base / "COLCON_IGNORE").exists():
        write_text_atomic(install_base / "COLCON_IGNORE", "")


def installed_in_order(install_base: Path, merged: bool) -> list[str]:
    """Packages installed in the base (built by roc or colcon) in the order colcon's setup scripts use."""
    base = str(install_base)
    try:
        prefixes = [base] if merged else [os.path.join(base, name) for name in sorted(os.listdir(base))]
    except OSError:  # no install base yet
        prefixes = []
    run_dependencies = {}
    for prefix in prefixes:  # os, not pathlib's glob: a no-op build of 100 packages spent 5 ms there
        folder = os.path.join(prefix, "share", "colcon-core", "packages")
        try:
            names = sorted(os.listdir(folder))
        except OSError:  # not a package's prefix (a file, COLCON_IGNORE) or one without markers
            continue
        for name in names:
            with open(os.path.join(folder, name)) as marker:
                text = marker.read().strip()
            run_dependencies[name] = set(text.split(":")) if text else set()
    return layered_order(run_dependencies, one_at_a_time=True)


SCRIPTS_STAMP = "roc_install_scripts.json"  # in the build base: what the install-level scripts were made from


def refresh_install_scripts(install_base: Path, merged: bool, build_base: Path | None = None) -> None:
    """The install-level setup scripts for every package now in the base, chained to the underlays
    the build used (roc.environment.chain). With a ``build_base``, scripts made from the same inputs
    (packages, layout, underlays, templates) and not touched since are left as they are: a no-op build
    renders nothing (and does not import Jinja)."""
    import hashlib
    import json
    import os

    from roc.environment import with_implicit_underlay
    from roc.environment.chain import chained_underlays

    underlays = chained_underlays(with_implicit_underlay(os.environ), install_base)
    packages = installed_in_order(install_base, merged)
    stamp = build_base / SCRIPTS_STAMP if build_base else None
    inputs = {"packages": packages, "merged": merged, "templates": _templates_stamp(),
              "underlays": [[u.prefix, hashlib.sha256(repr(u.operations).encode()).hexdigest()] for u in underlays]}
    if stamp is not None and stamp.is_file() and json.loads(stamp.read_text() or "{}") == {
            **inputs, "written": _scripts_stamp(install_base)}:
        return
    from roc.shell.scripts import write_install_scripts

    write_install_scripts(install_base, packages, merged, underlays)
    if stamp is not None:
        write_text_atomic(stamp, json.dumps({**inputs, "written": _scripts_stamp(install_base)}))


def _templates_stamp() -> list:
    import roc.shell

    folder = Path(roc.shell.__file__).parent / "templates"
    return sorted([p.name, p.stat().st_mtime_ns] for p in folder.iterdir())


def _scripts_stamp(install_base: Path) -> list:
    """When each install-level script was last written (None: missing)."""
    stamps = []
    for name in ("local_setup.sh", "local_setup.bash", "setup.sh", "setup.bash", "setup.zsh", "setup.ps1"):
        path = install_base / name
        stamps.append([name, path.stat().st_mtime_ns if path.exists() else None])
    return stamps
