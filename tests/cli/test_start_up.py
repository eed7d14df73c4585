"""What a command loads before it answers: the modules the quickest commands must not import (each
costs every run some milliseconds; bench/list_bench.py and bench/noop_bench.py measure the time)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from helpers.build import add_plain_package, copy_fixture, roc, ros_env

# roc's command (bin/roc), then the modules it loaded, on stderr
LOADED = """
import sys
sys.argv[0] = "roc"
from roc.cli.main import main
code = main()
print(" ".join(sorted(sys.modules)), file=sys.stderr)
sys.exit(code)
"""


def loaded_modules(workspace: Path, *argv: str) -> set[str]:
    result = subprocess.run([sys.executable, "-c", LOADED, *argv], cwd=workspace, env=ros_env(),
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
