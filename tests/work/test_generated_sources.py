"""Sources that rosidl generates during a build are the same in every build of the same package, so a
compiler cache (--compiler-cache) hits on them: roc fixes Python's string hash seed in the build
environment (rosidl orders a message's includes by iterating Python sets), unless the caller set one."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest
from helpers.build import REPO, roc, ros_env

from roc.builder.environment import build_environment
from roc.buildtypes.context import BuildOptions


def generated(workspace: Path) -> dict[str, str]:
    folder = workspace / "build" / "demo_interfaces" / "rosidl_generator_c"
    return {str(p.relative_to(folder)): p.read_text() for p in sorted(folder.rglob("*.c"))}


@pytest.mark.slow
def test_interface_sources_generated_in_two_builds_are_identical(tmp_path: Path) -> None:
    env = {k: v for k, v in ros_env().items() if k != "PYTHONHASHSEED"}
    sources = []
    for name in ("first", "second"):
        workspace = tmp_path / name
        shutil.copytree(REPO / "workspaces" / "example" / "src" / "demo_interfaces",
                        workspace / "src" / "demo_interfaces")
        built = roc("work", "build", cwd=workspace, env=env)
        assert built.returncode == 0, built.stdout + built.stderr
        sources.append(generated(workspace))
    assert sources[0] and sources[0] == sources[1]


def test_the_build_environment_fixes_the_hash_seed_unless_the_caller_set_one(monkeypatch) -> None:
    from roc.workspace.package import Package

    package = Package(name="p", path=Path("/src/p"), type="ros.ament_cmake")
    options = BuildOptions(build_base=Path("/b"), install_base=Path("/i"))
    monkeypatch.delenv("PYTHONHASHSEED", raising=False)
    assert build_environment(package, [], options)["PYTHONHASHSEED"] == "0"
    monkeypatch.setenv("PYTHONHASHSEED", "7")
    assert build_environment(package, [], options)["PYTHONHASHSEED"] == "7"
    assert os.environ["PYTHONHASHSEED"] == "7"
