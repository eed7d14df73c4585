"""Shared helpers for the build tests: run roc or colcon on a copy of a fixture workspace."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from helpers.rmw import middleware_prefixes, suite_environment
from roc import distribution

REPO = Path(__file__).resolve().parents[2]
FIXTURES = REPO / "workspaces" / "fixtures"
TESTS = REPO / "tests"
NODES = TESTS / "nodes"  # the scripts the tests run as ROS nodes
DATA = TESTS / "data"
BIN = Path(sys.executable).parent
# The ROS 2 distribution of the venv that runs the tests (scripts/setup.sh: .venv Jazzy, .venv-kilted Kilted)
DISTRO = distribution.current({}).name
REQUIREMENTS = REPO / "requirements" / f"ros-{DISTRO}.txt"  # its wheels, as scripts/setup.sh installed them
ENV_VARIABLES = ("AMENT_PREFIX_PATH", "CMAKE_PREFIX_PATH", "PYTHONPATH", "PATH", "LD_LIBRARY_PATH",
                 "COLCON_PREFIX_PATH")


def ros_env(**extra: str) -> dict[str, str]:
    """The environment of a developer who has ROS (the venv's wheels, and the middleware suite's RMW) as
    underlay."""
    env = {k: v for k, v in os.environ.items() if k not in ("COLCON_PREFIX_PATH", "AMENT_PREFIX_PATH")}
    env["AMENT_PREFIX_PATH"] = os.pathsep.join([*middleware_prefixes(), sys.prefix])
    env.update(suite_environment())
    env["PATH"] = f"{BIN}{os.pathsep}{env.get('PATH', '/usr/bin:/bin')}"
    env.update(extra)
    return env


SUITE_COMPILER_CACHE = ("CMAKE_C_COMPILER_LAUNCHER", "CMAKE_CXX_COMPILER_LAUNCHER", "CCACHE_DIR", "CCACHE_BASEDIR",
                        "CCACHE_NOHASHDIR", "CCACHE_SLOPPINESS", "CCACHE_MAXSIZE")


def share_compiles() -> None:
    """Have CMake compile through ccache (when installed) for the rest of the test run, in one cache
    under the temporary directory (concurrent use is safe), with paths under it made relative so that a
    workspace copied elsewhere compiles from the cache. Left alone when the caller chose a launcher."""
    if shutil.which("ccache") is None or "CMAKE_CXX_COMPILER_LAUNCHER" in os.environ:
        return
    temporary = tempfile.gettempdir()
    os.environ.update(CMAKE_C_COMPILER_LAUNCHER="ccache", CMAKE_CXX_COMPILER_LAUNCHER="ccache",
                      CCACHE_DIR=os.path.join(temporary, "roc-tests-ccache"), CCACHE_BASEDIR=temporary,
                      CCACHE_NOHASHDIR="true", CCACHE_MAXSIZE="2G",
                      CCACHE_SLOPPINESS="include_file_mtime,include_file_ctime,time_macros")


def without_suite_compiler_cache(env: dict[str, str]) -> dict[str, str]:
    """``env`` without share_compiles's variables (for tests of roc's own --compiler-cache)."""
    return {name: value for name, value in env.items() if name not in SUITE_COMPILER_CACHE}


def add_plain_package(ws, name: str, text: str | None = "v1", depends: str = "") -> None:
    """A plain CMake package ``src/NAME`` (no package.xml) with a config file ``find_package`` finds,
    installing ``value.txt`` holding ``text`` (none when None); ``depends``: CMake lines before the
    installs."""
    directory = ws / "src" / name
    directory.mkdir(parents=True, exist_ok=True)
    value = ""
    if text is not None:
        (directory / "value.txt").write_text(text)
        value = f"install(FILES value.txt DESTINATION share/{name})\n"
    (directory / "CMakeLists.txt").write_text(
        f"cmake_minimum_required(VERSION 3.8)\nproject({name} NONE)\n{depends}{value}"
        f"file(WRITE ${{CMAKE_CURRENT_BINARY_DIR}}/{name}Config.cmake \"\")\n"
        f"install(FILES ${{CMAKE_CURRENT_BINARY_DIR}}/{name}Config.cmake DESTINATION share/{name}/cmake)\n")


def copy_fixture(name: str, destination: Path) -> Path:
    shutil.copytree(FIXTURES / name, destination)
    return destination


def add_cmake_package(workspace: Path, name: str, cmakelists: str, depends: tuple[str, ...] = (),
                      test_depends: tuple[str, ...] = (), build_type: str = "cmake") -> None:
    """A CMake package ``src/NAME`` (plain, or ``build_type`` ament_cmake) with this CMakeLists.txt,
    ``<depend>``s and ``<test_depend>``s."""
    directory = workspace / "src" / name
    directory.mkdir(parents=True)
    deps = "".join(f"<depend>{d}</depend>" for d in depends)
    deps += "".join(f"<test_depend>{d}</test_depend>" for d in test_depends)
    (directory / "package.xml").write_text(
        f'<?xml version="1.0"?><package format="3"><name>{name}</name><version>0.0.1</version>'
        f'<description>test</description><maintainer email="roc@example.com">roc</maintainer>'
        f"<license>Apache-2.0</license>{deps}<export><build_type>{build_type}</build_type></export></package>")
    (directory / "CMakeLists.txt").write_text(cmakelists)


def roc(*args: str, cwd: Path, env: dict[str, str] | None = None, timeout: float = 600) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN / "roc"), *args], cwd=cwd, env=env or ros_env(), capture_output=True,
                          text=True, timeout=timeout)


def colcon(*args: str, cwd: Path, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN / "colcon"), *args], cwd=cwd, env=env or ros_env(), capture_output=True,
                          text=True, timeout=900)


def in_sourced_shell(workspace: Path, script: str, setup: str = "install/setup.bash",
                     strict: bool = True) -> subprocess.CompletedProcess:
    """Run ``script`` in a fresh bash that sourced ``setup`` (with ``set -u`` when ``strict``)."""
    env = {"HOME": os.environ.get("HOME", "/tmp"), "PATH": f"{BIN}:/usr/bin:/bin",
           "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    prelude = "set -eu; " if strict else ""
    return subprocess.run(["bash", "-c", f'{prelude}source "{setup}"; {script}'], cwd=workspace, env=env,
                          capture_output=True, text=True, timeout=120)


def sourced_values(workspace: Path, setup: str = "install/setup.bash", strict: bool = True) -> dict[str, str]:
    """The path-like variables after sourcing, with the workspace path replaced by WS."""
    script = "; ".join(f'echo "{v}=${{{v}:-}}"' for v in ENV_VARIABLES)
    result = in_sourced_shell(workspace, script, setup, strict)
    assert result.returncode == 0, result.stderr
    values = dict(line.split("=", 1) for line in result.stdout.splitlines())
    return {k: v.replace(str(workspace), "WS") for k, v in values.items()}


def without_own_underlay(values: dict[str, str]) -> dict[str, str]:
    """roc's sourced values less the entries of the venv's ROS 2, the underlay these tests build on:
    roc's setup scripts chain it and colcon's cannot (it has no local_setup script, see
    roc/environment/chain.py), the wheels' library folders included. PATH keeps it: the clean shell starts
    with the venv's bin."""
    from roc.environment.chain import wheel_library_operations

    assert values["AMENT_PREFIX_PATH"].split(os.pathsep)[-1] == sys.prefix, values["AMENT_PREFIX_PATH"]
    # the wheels' library folders outside the venv (the interpreter's libpython folder) are the venv's too
    libraries = {os.path.join(sys.prefix, op.values[0]) for op in wheel_library_operations(Path(sys.prefix))}

    def ours(entry: str) -> bool:
        return entry == sys.prefix or entry.startswith(sys.prefix + os.sep) or entry in libraries

    return {name: os.pathsep.join(e for e in value.split(os.pathsep) if name == "PATH" or not ours(e))
            for name, value in values.items()}


def installed_files(install: Path) -> set[str]:
    return {str(p.relative_to(install)) for p in install.rglob("*") if not p.is_dir()}


def comparable_install_files(install: Path) -> set[str]:
    """Installed files less the justified differences between roc and colcon: colcon's Python helpers
    for its setup scripts (roc bakes the order into the scripts) and byte-code caches (they depend on
    who imported what)."""
    return {f for f in installed_files(install) if not f.endswith(".pyc") and "_local_setup_util_" not in f}


def package_dsv_files(install: Path) -> dict[str, str]:
    return {str(p.relative_to(install)): p.read_text() for p in install.rglob("package.dsv")}


# Each test file that starts ROS participants has a slot of its own; a slot is one ROS domain per
# pytest-xdist worker, counted from ROC_TEST_DOMAIN_BASE (default 20). Two test runs on one machine (two
# checkouts, or a person beside a robot on domain 20) stay apart with, e.g., ROC_TEST_DOMAIN_BASE=90.
DOMAIN_SLOTS = 70
DOMAIN_MAX = 232  # Fast DDS's highest domain id (its UDP ports are derived from it)


def ros_domain_id(slot: int) -> str:
    """The ROS domain of ``slot`` (0 .. DOMAIN_SLOTS - 1) for this pytest-xdist worker."""
    assert 0 <= slot < DOMAIN_SLOTS, f"domain slot {slot}: raise DOMAIN_SLOTS in tests/helpers/build.py"
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    worker = int(os.environ.get("PYTEST_XDIST_WORKER", "gw0").removeprefix("gw") or 0)
    base = os.environ.get("ROC_TEST_DOMAIN_BASE", "20")
    if not base.isdigit():
        raise ValueError(f"ROC_TEST_DOMAIN_BASE={base!r}: expected a ROS domain id such as 20")
    domain = int(base) + slot * workers + worker
    if domain > DOMAIN_MAX:
        raise ValueError(f"ROC_TEST_DOMAIN_BASE={base}: this run needs domains up to "
                         f"{int(base) + DOMAIN_SLOTS * workers - 1}, above {DOMAIN_MAX}; choose a lower base")
    return str(domain)


def stop_process(process: subprocess.Popen) -> None:
    """Stop a process the test started (by its PID): terminate, then kill if it does not exit."""
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
