"""python and ament_python packages: one ``setup.py`` run that builds and installs into the prefix.

colcon starts Python two extra times per package (to list setuptools commands and to read the
setup() arguments); roc runs setup.py once. Nothing is written into the source tree: egg-info and
build files go to the build directory. ``--symlink-install`` then replaces installed files that are
byte-for-byte copies of source files with symlinks to them, so edits show without rebuilding.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from roc.buildtypes.context import BuildOptions, PackageJob
from roc.engine.process import TaskContext, TaskError
from roc.fsutil import file_sha256


def python_lib(prefix: Path) -> Path:
    """``<prefix>/lib/pythonX.Y/site-packages``."""
    import sysconfig  # here: a no-op build does not need it

    return Path(sysconfig.get_path("purelib", "posix_prefix", vars={"base": str(prefix), "platbase": str(prefix)}))


def _install_scripts(source: Path, prefix: Path) -> str | None:
    """setup.cfg's ``[install] install_scripts`` (setuptools ignores it inside a venv, so pass it)."""
    setup_cfg = source / "setup.cfg"
    if not setup_cfg.is_file():
        return None
    import configparser

    parser = configparser.ConfigParser(interpolation=None)
    parser.read(setup_cfg)
    value = parser.get("install", "install_scripts", fallback=None) or parser.get("install", "install-scripts",
                                                                                  fallback=None)
    return value.replace("$base", str(prefix)) if value else None


def build_python(context: TaskContext, job: PackageJob, options: BuildOptions) -> None:
    job.build_dir.mkdir(parents=True, exist_ok=True)
    lib = python_lib(job.prefix)
    lib.mkdir(parents=True, exist_ok=True)
    job.env["PYTHONPATH"] = os.pathsep.join(p for p in (str(lib), job.env.get("PYTHONPATH", "")) if p)
    record = job.build_dir / "install.log"
    if not options.symlink_install:
        unlink_symlinks(record)
    command = [
        # setuptools' deprecation notices of these commands, silenced as colcon silences them
        sys.executable, "-W", "ignore:setup.py install is deprecated",
        "-W", "ignore:easy_install command is deprecated",
        "setup.py",
        "egg_info", "--egg-base", str(job.build_dir),
        "build", "--build-base", str(job.build_dir / "build"),
        "install", "--prefix", str(job.prefix), "--record", str(record), "--single-version-externally-managed",
    ]
    scripts = _install_scripts(job.source, job.prefix)
    if scripts:
        command += ["--install-scripts", scripts]
    if context.run(command, cwd=str(job.source), env=job.env) != 0:
        raise TaskError("setup.py install failed")
    if options.symlink_install:
        link_to_sources(job.source, record)


def unlink_symlinks(record: Path) -> None:
    """Remove the symlinks a ``--symlink-install`` build left in place of installed files: setup.py
    would leave them (it copies through them onto the source file itself)."""
    if record.is_file():
        for line in record.read_text().splitlines():
            if line and Path(line).is_symlink():
                Path(line).unlink()


def link_to_sources(source: Path, record: Path) -> None:
    """Replace installed copies of source files (same name, same bytes) with symlinks to them."""
    by_name: dict[str, list[Path]] = {}
    for dirpath, dirnames, filenames in os.walk(source):
        dirnames[:] = [d for d in dirnames if not d.startswith(".") and d not in ("build", "__pycache__")]
        for name in filenames:
            by_name.setdefault(name, []).append(Path(dirpath, name))
    for line in record.read_text().splitlines():
        installed = Path(line)
        candidates = by_name.get(installed.name, [])
        if not candidates or installed.is_symlink() or not installed.is_file():
            continue
        digest = file_sha256(installed)
        matches = [c for c in candidates if file_sha256(c) == digest]
        if len(matches) == 1:
            temporary = installed.with_name(f".{installed.name}.roc-link")
            temporary.unlink(missing_ok=True)
            temporary.symlink_to(matches[0].resolve())
            os.replace(temporary, installed)
