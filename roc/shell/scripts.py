"""Write the scripts that make installed packages usable: hooks, package scripts, setup scripts.

The per-package ``.dsv`` files are the source of truth (colcon reads them too); roc bakes their
resolved operations into plain shell, so sourcing needs no Python and no per-package subshell.
"""

from __future__ import annotations

import re
import shlex
from functools import lru_cache
from pathlib import Path

from roc.environment.dsv import Operation, resolve_operations
from roc.fsutil import write_text_atomic

SHELLS = ("sh", "bash", "zsh")


@lru_cache(maxsize=1)
def _templates():
    import jinja2

    environment = jinja2.Environment(
        loader=jinja2.PackageLoader("roc.shell", "templates"), keep_trailing_newline=True,
        undefined=jinja2.StrictUndefined, autoescape=False,
    )
    environment.filters["shquote"] = lambda value: shlex.quote(str(value))
    # for values inside "...": keeps spaces and any characters, expands nothing
    environment.filters["dquote"] = lambda value: re.sub(r'([\\"$`])', r"\\\1", str(value))
    return environment


def render(template: str, **values) -> str:
    return _templates().get_template(template).render(**values)


def write_hook(prefix: Path, package: str, name: str, line: str) -> str:
    """Write ``share/<package>/hook/<name>.dsv`` (and its .sh twin); returns its path below ``prefix``."""
    relative = f"share/{package}/hook/{name}"
    write_text_atomic(prefix / f"{relative}.dsv", line + "\n")
    kind, variable, value = line.split(";", 2)
    operation = Operation(kind, variable, (value,))
    write_text_atomic(prefix / f"{relative}.sh", render("package.sh.j2", package=package, prefix=prefix,
                                                          operations=[operation]))
    return relative


def write_package_scripts(prefix: Path, package: str, hooks: list[str]) -> None:
    """``share/<package>/package.{dsv,sh,bash,zsh}``: the hooks (files below ``prefix``), then the
    package's own local_setup."""
    share = prefix / "share" / package
    lines = [f"source;{hook}" for hook in hooks]
    lines += [f"source;share/{package}/local_setup.{ext}" for ext in ("bash", "dsv", "sh", "zsh")
              if (share / f"local_setup.{ext}").exists()]
    write_text_atomic(share / "package.dsv", "".join(f"{line}\n" for line in lines))
    operations = resolve_operations(prefix, share / "package.dsv")
    write_text_atomic(share / "package.sh", render("package.sh.j2", package=package, prefix=prefix,
                                                   operations=operations))
    for shell in ("bash", "zsh"):
        write_text_atomic(share / f"package.{shell}", render("package.shell.j2", package=package, shell=shell))


def write_install_scripts(base: Path, packages: list[str], merged: bool, underlays: list[str]) -> None:
    """Install-level ``local_setup.*`` (``packages`` in dependency order) and ``setup.*`` scripts."""
    write_text_atomic(base / "local_setup.sh", render("local_setup.sh.j2", base=base, packages=packages,
                                                      merged=merged))
    for shell in ("bash", "zsh"):
        write_text_atomic(base / f"local_setup.{shell}", render("local_setup.shell.j2", shell=shell))
    chain = [u for u in reversed(underlays) if Path(u) != base]
    for shell in SHELLS:
        write_text_atomic(base / f"setup.{shell}", render("setup.sh.j2", shell=shell, base=base, underlays=chain))
