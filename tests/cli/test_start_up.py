"""What a command loads before it answers: the modules the quickest commands must not import (each
costs every run some milliseconds; bench/list_bench.py and bench/noop_bench.py measure the time)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from helpers.build import add_plain_package, copy_fixture, roc, ros_env
from helpers.graph import graph_env

SLOT = 69

# roc's command (bin/roc), then the modules it loaded, on stderr
LOADED = """
import sys
sys.argv[0] = "roc"
from roc.cli.main import main
code = main()
print(" ".join(sorted(sys.modules)), file=sys.stderr)
sys.exit(code)
"""


def loaded_modules(workspace: Path, *argv: str, env: dict[str, str] | None = None) -> set[str]:
    result = subprocess.run([sys.executable, "-c", LOADED, *argv], cwd=workspace, env=env or ros_env(),
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    return set(result.stderr.splitlines()[-1].split())


def test_listing_a_cached_workspace_loads_no_dataclasses_typing_threads_or_parsers(tmp_path: Path) -> None:
    workspace = copy_fixture("cmake", tmp_path / "cmake")
    first = loaded_modules(workspace, "work", "list", "-t")  # discovers, and fills the cache
    assert "lxml.etree" in first or "roc.workspace.discovery" in first
    cached = loaded_modules(workspace, "work", "list", "-t")
    assert not cached & {"dataclasses", "typing", "threading", "roc.workspace.discovery", "lxml.etree", "yaml",
                         "json", "concurrent.futures"}


@pytest.mark.slow  # builds a package first
def test_a_no_op_build_loads_no_dataclasses_typing_thread_pool_logging_or_python_packaging(tmp_path: Path) -> None:
    add_plain_package(tmp_path, "plain")
    assert roc("work", "build", cwd=tmp_path).returncode == 0
    # the first build made build/, install/ and log/ in the root: the next command discovers again
    assert roc("work", "build", cwd=tmp_path).returncode == 0
    loaded = loaded_modules(tmp_path, "work", "build")
    assert "roc.engine.executor" in loaded  # the engine ran, and found the package up to date
    assert not loaded & {"concurrent.futures", "logging", "sysconfig", "configparser", "traceback", "dataclasses", "typing"}


def test_a_graph_query_loads_no_message_code_generator_numpy_or_action_client(tmp_path: Path) -> None:
    """What a first query without the daemon needs of rclpy, and no more: a process's first message imports
    its type support through rosidl_generator_py, whose __init__ also imports the message code generator
    (lark: 50 ms), which roc leaves out (roc.rclpy_guard.load_type_support_importer); numpy comes with
    rmw_dds_common's Python messages and with rclpy.action (0.1 s), which the graph needs neither of."""
    loaded = loaded_modules(tmp_path, "topic", "list", "--no-daemon", env=graph_env(SLOT, tmp_path))
    assert {"rclpy.node", "rosidl_generator_py.import_type_support_impl"} <= loaded  # the type support came through it
    assert not loaded & {"lark", "rosidl_generator_py.generate_py_impl", "numpy", "rclpy.action"}


GENERATOR_ASKED_FOR = """
import sys
from roc.rclpy_guard import guard_rclpy_import
guard_rclpy_import()
import rclpy
from rosidl_generator_py import generate_py, import_type_support
print(generate_py.__module__, import_type_support.__module__)
"""


def test_the_code_generator_still_loads_when_asked_for() -> None:
    done = subprocess.run([sys.executable, "-c", GENERATOR_ASKED_FOR], env=ros_env(), capture_output=True, text=True,
                          timeout=60)
    assert done.stdout.split() == ["rosidl_generator_py.generate_py_impl",
                                   "rosidl_generator_py.import_type_support_impl"], done.stderr
