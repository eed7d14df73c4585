"""Write the scripts that make installed packages usable: hooks, package scripts, setup scripts.

The per-package ``.dsv`` files are the source of truth (colcon reads them too); roc bakes their
resolved operations into plain shell, so sourcing needs no Python and no per-package subshell.
"""

from __future__ import annotations

import re
import shlex
from functools import lru_cache
from pathlib import Path

from roc.environment.chain import Underlay
from roc.environment.dsv import Operation, resolve_operations
from roc.fsutil import write_text_atomic
from roc.templates import template_environment

SHELLS = ("sh", "bash", "zsh")


@lru_cache(maxsize=1)
def _templates():
    return template_environment("roc.shell", {
        "shquote": lambda value: shlex.quote(str(value)),
        # for values inside "...": keeps spaces and any characters, expands nothing
        "dquote": lambda value: re.sub(r'([\\"$`])', r"\\\1", str(value)),
        "psquote": _powershell_literal,
    })


def _powershell_literal(value: object) -> str:
    """A PowerShell '...' string: expands nothing; its quote characters (PowerShell counts the
    typographic ones too) are doubled."""
    return "'" + re.sub("(['\u2018\u2019\u201a\u201b])", r"\1\1", str(value)) + "'"


def render(template: str, **values) -> str:
    return _templates().get_template(template).render(**values)


def _package_script(shell: str, package: str, prefix: Path, operations: list[Operation], depth: int) -> str:
    """A script applying ``operations`` in ``shell`` ("sh" or "ps1"), placed ``depth`` directories
    below the prefix; of the ``source`` operations it runs only the scripts written for that shell."""
    suffix = f".{shell}"
    operations = [op for op in operations if op.kind != "source" or op.name.endswith(suffix)]
    return render(f"package{suffix}.j2", package=package, prefix=prefix, operations=operations,
                  up="/".join([".."] * depth))


def write_hook(prefix: Path, package: str, name: str, line: str) -> list[str]:
    """Write ``share/<package>/hook/<name>.dsv`` and its .ps1 and .sh twins; returns their paths below
    ``prefix`` in the order colcon lists them in package.dsv."""
    relative = f"share/{package}/hook/{name}"
    write_text_atomic(prefix / f"{relative}.dsv", line + "\n")
    kind, variable, value = line.split(";", 2)
    operations = [Operation(kind, variable, (value,))]
    for shell in ("ps1", "sh"):
        write_text_atomic(prefix / f"{relative}.{shell}", _package_script(shell, package, prefix, operations, 3))
    return [f"{relative}.{ext}" for ext in ("ps1", "dsv", "sh")]


def write_package_scripts(prefix: Path, package: str, hooks: list[str]) -> None:
    """``share/<package>/package.{dsv,sh,bash,zsh,ps1}`` applying ``hooks`` (files below ``prefix``)."""
    share = prefix / "share" / package
    lines = [f"source;{hook}" for hook in hooks]
    write_text_atomic(share / "package.dsv", "".join(f"{line}\n" for line in lines))
    operations = resolve_operations(prefix, share / "package.dsv")
    for shell in ("ps1", "sh"):
        write_text_atomic(share / f"package.{shell}", _package_script(shell, package, prefix, operations, 2))
    for shell in ("bash", "zsh"):
        write_text_atomic(share / f"package.{shell}", render("package.shell.j2", package=package, shell=shell))


def write_install_scripts(base: Path, packages: list[str], merged: bool, underlays: list[Underlay]) -> None:
    """Install-level ``local_setup.*`` (``packages`` in dependency order) and ``setup.*`` scripts, the
    latter chaining ``underlays`` (highest priority first: they are applied in reverse order)."""
    for shell in ("sh", "ps1"):
        write_text_atomic(base / f"local_setup.{shell}", render(f"local_setup.{shell}.j2", base=base,
                                                                packages=packages, merged=merged))
    for shell in ("bash", "zsh"):
        write_text_atomic(base / f"local_setup.{shell}", render("local_setup.shell.j2", shell=shell))
    chain = list(reversed(underlays))
    for shell in SHELLS:
        write_text_atomic(base / f"setup.{shell}", render("setup.sh.j2", shell=shell, base=base, underlays=chain))
    write_text_atomic(base / "setup.ps1", render("setup.ps1.j2", underlays=chain))
