"""cmake and ament_cmake packages: configure when needed, build, install.

Configure runs only when there is no CMake cache, the arguments changed (``cmake_args.last``, as
colcon keeps it) or it is forced; when the compilers or the build program changed, with a new cache.
Switching ``--symlink-install`` on or off cleans what the other mode left (see
``switch_install_mode``). Makefile builds take part in roc's global jobserver.
"""

from __future__ import annotations

import json
import os
import re
import shutil
from pathlib import Path

from roc.builder.fingerprint import build_tools
from roc.buildtypes.context import BuildOptions, PackageJob
from roc.engine.process import TaskContext, TaskError
from roc.fsutil import write_text_atomic

TOOLS_FILE = "roc_cmake_tools.last"  # the programs of the last configure (see _configure_tools)
LAUNCHER = "_COMPILER_LAUNCHER="  # in the arguments --compiler-cache adds


def cmake_arguments(job: PackageJob, options: BuildOptions) -> list[str]:
    args = [*options.cmake_args_for(job.package.name)]
    if job.package.build_type == "ament_cmake":
        args += options.ament_cmake_args_for(job.package.name)
        if options.symlink_install:
            args.append("-DAMENT_CMAKE_SYMLINK_INSTALL=1")
    return args + job.cmake_args


def _cache_value(build_dir: Path, key: str) -> str | None:
    try:
        text = (build_dir / "CMakeCache.txt").read_text(errors="replace")
    except OSError:
        return None
    match = re.search(rf"^{re.escape(key)}:[A-Z]+=(.*)$", text, re.MULTILINE)
    return match.group(1) if match else None


# The files a CMake install wrote: CMake's own list, and ament_cmake's list of the symlinks it made.
INSTALL_MANIFESTS = ("install_manifest.txt", "symlink_install_manifest.txt")


def switch_install_mode(build_dir: Path, prefix: Path, symlink_install: bool) -> None:
    """``--symlink-install`` switched on or off since the last configure of an ament_cmake package:
    remove what the last install wrote (CMake would keep an installed symlink that points at its
    source file, and ament_cmake cannot put a symlink where a directory was installed) and the CMake
    cache (which would keep ``AMENT_CMAKE_SYMLINK_INSTALL``), so the package configures and installs
    afresh in the new mode. ament_cmake_python's copies of (or symlinks to) Python packages in the
    build directory that do not fit the mode go too, also after a switch that failed half-way (a copy
    made over a symlink would write into the sources)."""
    cached = _cache_value(build_dir, "AMENT_CMAKE_SYMLINK_INSTALL")
    if cached is not None and (cached.upper() in ("1", "ON", "TRUE", "YES")) != symlink_install:
        for name in INSTALL_MANIFESTS:
            manifest = build_dir / name
            if manifest.is_file():
                for line in manifest.read_text().splitlines():
                    _remove_installed(Path(line.strip()), prefix)
                manifest.unlink()
        (build_dir / "CMakeCache.txt").unlink()
    for item in (build_dir / "ament_cmake_python").glob("*/*"):
        if item.name != "setup.py" and not item.name.endswith(".egg-info") and item.is_symlink() != symlink_install:
            _remove_tree(item)


def _remove_tree(path: Path) -> None:
    """Remove a file, symlink or directory tree (a symlink itself, never what it points to)."""
    if path.is_symlink() or path.is_file():
        path.unlink()
    elif path.is_dir():
        shutil.rmtree(path)


def _remove_installed(path: Path, prefix: Path) -> None:
    """Remove an installed file or symlink, then its parent directories inside ``prefix`` that are
    left empty (never anything outside the prefix)."""
    if not path.is_absolute() or prefix not in path.parents:
        return
    _remove_tree(path)
    parent = path.parent
    while parent != prefix and prefix in parent.parents:
        try:
            parent.rmdir()
        except OSError:  # not empty (or already gone): stop
            break
        parent = parent.parent


def _has_target(build_dir: Path, target: str) -> bool:
    """Whether the generated build system has ``target`` (Makefile or Ninja)."""
    makefile = build_dir / "Makefile"
    if makefile.exists():
        return re.search(rf"^{re.escape(target)}:", makefile.read_text(errors="replace"), re.MULTILINE) is not None
    ninja = build_dir / "build.ninja"
    if ninja.exists():
        return re.search(rf"^build {re.escape(target)}:", ninja.read_text(errors="replace"), re.MULTILINE) is not None
    return False


def _check(context: TaskContext, job: PackageJob, command: list[str], what: str,
           env: dict[str, str] | None = None) -> None:
    if context.run(command, cwd=str(job.build_dir), env=env or job.env, pass_fds=job.pass_fds) != 0:
        raise TaskError(f"{what} failed")


def _install_env(env: dict[str, str]) -> dict[str, str]:
    """CMake's install skips a file whose installed copy has its modification time, which it keeps only
    to the second: a file rebuilt within the second of the last install would stay uninstalled (and
    the packages above would build against the old one). CMAKE_INSTALL_ALWAYS copies every file; the
    copies keep their sources' times, so the makes above see nothing new. A user's own setting wins."""
    return {"CMAKE_INSTALL_ALWAYS": "1", **env}


def build_cmake(context: TaskContext, job: PackageJob, options: BuildOptions) -> None:
    build_dir = job.build_dir
    build_dir.mkdir(parents=True, exist_ok=True)
    args = cmake_arguments(job, options)
    last_args = build_dir / "cmake_args.last"
    recorded = repr(args) if args else "None"
    tools = _configure_tools(job, args)
    last_tools = build_dir / TOOLS_FILE
    launcher_dropped = last_args.exists() and LAUNCHER in last_args.read_text() and LAUNCHER not in recorded
    if options.cmake_clean_cache or launcher_dropped or (last_tools.exists() and last_tools.read_text() != tools):
        # A cache keeps the compilers and build program of its first configure, and a compiler launcher
        # (--compiler-cache) once set: start a new one.
        (build_dir / "CMakeCache.txt").unlink(missing_ok=True)
        shutil.rmtree(build_dir / "CMakeFiles", ignore_errors=True)
    if job.package.build_type == "ament_cmake":
        switch_install_mode(build_dir, job.prefix, options.symlink_install)
    needs_configure = (
        options.cmake_force_configure
        or not (build_dir / "CMakeCache.txt").exists()
        or not last_args.exists()
        or last_args.read_text() != recorded
    )
    if needs_configure:
        command = ["cmake", str(job.source), *args, f"-DCMAKE_INSTALL_PREFIX={job.prefix}"]
        _check(context, job, command, "CMake configure")
        write_text_atomic(last_args, recorded)
        write_text_atomic(last_tools, tools)
    targets = []
    if options.cmake_clean_first:
        targets.append("clean")
    if options.cmake_target:
        if not _has_target(build_dir, options.cmake_target):
            if options.cmake_target_skip_unavailable:
                return
            raise TaskError(f"the package has no target '{options.cmake_target}'")
        targets.append(options.cmake_target)
    else:
        targets.append("")  # the default target
    for target in targets:
        _check(context, job, _build_command(job, options, target), f"building target '{target or 'all'}'")
    if not options.cmake_target and _has_target(build_dir, "install"):
        _check(context, job, ["cmake", "--install", str(build_dir)], "install", env=_install_env(job.env))


def _configure_tools(job: PackageJob, args: list[str]) -> str:
    """The programs a first configure records in CMakeCache.txt (compilers, the generator's build
    program, as build_tools names them), resolved on the build's PATH: when they change, the package
    is configured afresh so that the new ones are used."""
    path = job.env.get("PATH")
    found = {}
    for tool in build_tools(job.package.build_type, job.env, tuple(args)):
        location = shutil.which(tool, path=path)
        found[tool] = os.path.realpath(location) if location else None
    return json.dumps(found, sort_keys=True)


def _build_command(job: PackageJob, options: BuildOptions, target: str) -> list[str]:
    generator = _cache_value(job.build_dir, "CMAKE_GENERATOR") or ""
    if generator == "Unix Makefiles" and job.make_flags:
        make = _cache_value(job.build_dir, "CMAKE_MAKE_PROGRAM") or shutil.which("make") or "make"
        # Run make directly so that it inherits the jobserver's file descriptors.
        job.env["MAKEFLAGS"] = job.make_flags
        return [make, *([target] if target else [])]
    command = ["cmake", "--build", str(job.build_dir)]
    if target:
        command += ["--target", target]
    if "Ninja" in generator or generator == "Unix Makefiles":
        command += ["--", f"-j{options.jobs_per_package}"]
    return command

