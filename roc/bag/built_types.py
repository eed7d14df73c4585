"""Message types a bag holds that this environment lacks, built from the bag's own definitions.

rclpy (Jazzy) can publish only a type whose generated code is installed, so ``roc bag play`` turns
the ``ros2msg`` definitions a bag stores (the type's ``.msg`` text and each type it uses) into
interface packages, one per missing package, and builds them with ``roc work build`` into roc's
cache, keyed by the definitions' text: the first play takes a build (seconds), later ones none. A
package that is installed is depended on, never rebuilt. The result is an install prefix; the
generated libraries load only through the environment a process starts with, so the verb starts
itself again with that prefix sourced (``environment_with``)."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
from collections.abc import Callable, Iterable
from pathlib import Path

from roc.bag.definitions import message_sections, msg_dependencies
from roc.bag.message import Definition
from roc.environment.chain import prefix_operations
from roc.environment.dsv import apply_operations
from roc.errors import RocError
from roc.fsutil import write_text_atomic
from roc.ros.types import UnknownTypeError, interface_packages, message_class
from roc.workspace.cache import cache_directory

BUILT_PREFIX_VARIABLE = "ROC_BAG_BUILT_TYPES"  # set in the verb started again: build no more


def _installed(type_name: str) -> bool:
    try:
        message_class(type_name)
    except UnknownTypeError:
        return False
    return True


def packages_to_build(definitions: Iterable[Definition]) -> dict[str, dict[str, str]]:
    """``{package: {Type: msg text}}`` of every package some definition needs and no installed
    package provides. Raises RocError when an installed package lacks a type a bag uses (another
    version of it), since building that package again would hide the installed one."""
    sections: dict[str, str] = {}
    for definition in definitions:
        for name, text in message_sections(definition).items():
            sections.setdefault(name, text)
    wanted: dict[str, dict[str, str]] = {}
    indexed = interface_packages()
    installed_packages: dict[str, bool] = {}
    for name, text in sorted(sections.items()):
        package, _, short = name.split("/")
        if package not in installed_packages:
            installed_packages[package] = package in indexed or any(
                _installed(n) for n in sections if n.startswith(f"{package}/"))
        if installed_packages[package]:
            if not _installed(name):
                raise RocError(f"the bag uses {name}, which the installed package '{package}' does not have "
                               "(another version of it?): install the version the bag was recorded with")
            continue
        wanted.setdefault(package, {})[short] = text
    return wanted


def _package_xml(package: str, dependencies: list[str]) -> str:
    depends = "".join(f"  <depend>{d}</depend>\n" for d in dependencies)
    return (f'<?xml version="1.0"?>\n<package format="3">\n  <name>{package}</name>\n  <version>0.0.0</version>\n'
            f"  <description>{package}, built by roc from a bag's own message definitions</description>\n"
            "  <maintainer email=\"roc@example.com\">roc</maintainer>\n  <license>unknown</license>\n"
            "  <buildtool_depend>ament_cmake</buildtool_depend>\n"
            "  <buildtool_depend>rosidl_default_generators</buildtool_depend>\n"
            f"{depends}  <exec_depend>rosidl_default_runtime</exec_depend>\n"
            "  <member_of_group>rosidl_interface_packages</member_of_group>\n"
            "  <export><build_type>ament_cmake</build_type></export>\n</package>\n")


def _cmake_lists(package: str, types: list[str], dependencies: list[str]) -> str:
    finds = "".join(f"find_package({d} REQUIRED)\n" for d in dependencies)
    files = "".join(f'  "msg/{t}.msg"\n' for t in types)
    listed = f"  DEPENDENCIES {' '.join(dependencies)}\n" if dependencies else ""
    return (f"cmake_minimum_required(VERSION 3.8)\nproject({package})\n\nfind_package(ament_cmake REQUIRED)\n"
            f"find_package(rosidl_default_generators REQUIRED)\n{finds}\n"
            f"rosidl_generate_interfaces(${{PROJECT_NAME}}\n{files}{listed})\n\n"
            "ament_export_dependencies(rosidl_default_runtime)\nament_package()\n")


def write_sources(packages: dict[str, dict[str, str]], src: Path) -> None:
    """An interface package for each of ``packages`` below ``src``."""
    for package, types in packages.items():
        dependencies = sorted({d.split("/")[0] for text in types.values() for d in msg_dependencies(text, package)}
                              - {package})
        root = src / package
        (root / "msg").mkdir(parents=True)
        for short, text in types.items():
            (root / "msg" / f"{short}.msg").write_text(text)
        (root / "package.xml").write_text(_package_xml(package, dependencies))
        (root / "CMakeLists.txt").write_text(_cmake_lists(package, sorted(types), dependencies))


def _build(workspace: Path) -> tuple[int, str]:
    """``roc work build`` of ``workspace``: its exit code and output. Ctrl+C, SIGTERM or a closed
    terminal stop the build (SIGTERM: it stops its own processes) and raise KeyboardInterrupt."""
    def interrupted(*_) -> None:
        raise KeyboardInterrupt

    handlers = {number: signal.signal(number, interrupted) for number in (signal.SIGTERM, signal.SIGHUP)}
    build = subprocess.Popen([sys.executable, "-m", "roc", "work", "build", "--merge-install"], cwd=workspace,
                             stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        output, _ = build.communicate()
    except BaseException:
        build.terminate()
        build.wait()
        raise
    finally:
        for number, handler in handlers.items():
            signal.signal(number, handler)
    return build.returncode, output


def built_prefix(definitions: Iterable[Definition], report: Callable[[str], None]) -> Path | None:
    """The install prefix of the packages the bag needs and this environment lacks (built now if the
    cache does not have them yet), or None when nothing is missing."""
    packages = packages_to_build(definitions)
    if not packages:
        return None
    key = hashlib.sha256(json.dumps(packages, sort_keys=True).encode()).hexdigest()[:20]
    prefix = cache_directory() / "bag-types" / key
    if (prefix / "share" / "ament_index").is_dir():
        return prefix
    names = ", ".join(sorted(packages))
    report(f"building {names} from the bag's own definitions (not installed here; once, into {prefix})")
    work = prefix.with_name(f"{key}.{os.getpid()}.building")
    shutil.rmtree(work, ignore_errors=True)
    try:
        write_sources(packages, work / "src")
        returncode, output = _build(work)
        if returncode != 0:
            log = prefix.with_name(f"{key}.failed.log")
            write_text_atomic(log, output)
            raise RocError(f"building {names} from the bag's definitions failed (output in {log}); install or "
                           "source the packages the bag was recorded with")
        try:
            (work / "install").rename(prefix)  # whole or not at all; another player may have won the race
        except OSError:
            if not (prefix / "share" / "ament_index").is_dir():
                raise
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return prefix


def environment_with(prefix: Path, environ: dict[str, str]) -> dict[str, str]:
    """``environ`` with ``prefix`` sourced, marked so that the process it starts builds no more."""
    env = dict(environ)
    apply_operations(env, prefix, list(prefix_operations(prefix)))
    env[BUILT_PREFIX_VARIABLE] = str(prefix)
    return env
