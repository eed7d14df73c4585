"""What ``roc work clean`` removes: whole bases, or the selected packages' directories in them, and never
anything outside the workspace's bases."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

from roc.errors import RocError

BASES = ("build", "install", "log", "test_result")


def base_directories(args, root: Path) -> dict[str, Path]:
    """Each base by name, as the options give it (relative to the workspace root)."""
    values = {"build": args.build_base, "install": args.install_base, "log": args.log_base,
              "test_result": args.test_result_base}
    return {name: root / value for name, value in values.items() if value != os.devnull}


def chosen_bases(args) -> list[str]:
    return [name for name in args.base_select if name not in args.base_ignore]


def package_directories(base_name: str, base: Path, package: str, merged: bool) -> list[Path]:
    """A package's directories in one base: none in the log base (logs are per run) or in a merged
    install base (its files are mixed with the other packages')."""
    if base_name == "log" or (base_name == "install" and merged):
        return []
    return [base / package]


def check_inside(path: Path, base: Path) -> None:
    """Refuse a path that is not strictly inside its base once symlinks are resolved (the entry itself
    may be a symlink: only the link is removed)."""
    real_base = base.resolve()
    real_parent = path.parent.resolve()
    if real_parent != real_base and real_base not in real_parent.parents:
        raise RocError(f"'{path}' is outside the base '{base}'; nothing was removed")
    if path.name in ("", ".", ".."):
        raise RocError(f"'{path}' is not a directory inside the base '{base}'; nothing was removed")


def remove(path: Path) -> None:
    """Remove a directory tree, a file, or a symlink (never what the link points to)."""
    if path.is_symlink() or not path.is_dir():
        path.unlink(missing_ok=True)
    else:
        shutil.rmtree(path)
