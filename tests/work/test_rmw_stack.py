"""rmw_cyclonedds as ``bash scripts/setup.sh --with-cyclonedds`` leaves it (built by roc on the Jazzy wheels
against Debian's cyclonedds-dev, tests/helpers/rmw.py): the ament index names it as a middleware, its
library resolves with the wheels' libraries, and an unchanged set-up has nothing to build."""

from __future__ import annotations

import subprocess
import sys

import pytest
from helpers.build import BIN, ros_env
from helpers.rmw import CYCLONEDDS, STACK, require_cyclonedds

pytestmark = pytest.mark.rmw


def test_rmw_cyclonedds_is_a_middleware_of_the_ament_index_and_its_library_resolves() -> None:
    prefix = require_cyclonedds()
    assert (prefix / "share" / "ament_index" / "resource_index" / "rmw_typesupport" / CYCLONEDDS).is_file()
    library = prefix / "lib" / f"lib{CYCLONEDDS}.so"
    wheels = ":".join([f"{sys.prefix}/lib", *map(str, (BIN.parent / "lib").glob("python3*/site-packages/ros_*.libs"))])
    linked = subprocess.run(["ldd", str(library)], env={"LD_LIBRARY_PATH": wheels}, capture_output=True, text=True)
    assert linked.returncode == 0, linked.stderr
    assert "not found" not in linked.stdout, linked.stdout
    assert "libddsc.so" in linked.stdout


def test_an_unchanged_rmw_stack_has_nothing_to_build() -> None:
    require_cyclonedds()
    explained = subprocess.run([str(BIN / "roc"), "-C", str(STACK / "stack"), "work", "build", "--explain",
                                "--cmake-args", "-DCMAKE_BUILD_TYPE=Release", "-DBUILD_TESTING=OFF"],
                               env=ros_env(), capture_output=True, text=True, timeout=60)
    assert explained.returncode == 0, explained.stderr
    assert explained.stdout.splitlines() == [f"{CYCLONEDDS}: up to date"], explained.stdout
