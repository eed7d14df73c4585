"""``roc work clean``: exactly the selected directories, never a path outside the bases."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from helpers.build import BIN, add_cmake_package, roc, ros_env

MANIFEST = """<?xml version="1.0"?>
<package format="3"><name>{name}</name><version>0.1.0</version><description>d</description>
<maintainer email="m@example.com">m</maintainer><license>MIT</license>
<export><build_type>ament_cmake</build_type></export></package>
"""


@pytest.fixture
def workspace(tmp_path: Path) -> Path:
    """Packages a, b and c with fake build, install and log directories; build/c and install/c are
    symlinks to directories outside the workspace."""
    root = tmp_path / "ws"
    outside = tmp_path / "outside"
    for name in ("a", "b", "c"):
        (root / "src" / name).mkdir(parents=True)
        (root / "src" / name / "package.xml").write_text(MANIFEST.format(name=name))
        (outside / name / "keep").mkdir(parents=True)
    for name in ("a", "b"):
        for base in ("build", "install"):
            (root / base / name / "sub").mkdir(parents=True)
            (root / base / name / "sub" / "file").write_text("x")
    (root / "build" / "c").symlink_to(outside / "c")
    (root / "install" / "c").symlink_to(outside / "c")
    (root / "build" / "a" / "sub" / "link_out").symlink_to(outside / "a")
    (root / "log" / "build_1").mkdir(parents=True)
    return root


def test_packages_removes_exactly_the_selected(workspace: Path) -> None:
    result = roc("work", "clean", "packages", "--packages-select", "a", "c", "-y", cwd=workspace)
    assert result.returncode == 0, result.stderr
    assert not (workspace / "build" / "a").exists() and not (workspace / "install" / "a").exists()
    assert not (workspace / "build" / "c").is_symlink() and not (workspace / "install" / "c").is_symlink()
    assert (workspace / "build" / "b" / "sub" / "file").exists() and (workspace / "install" / "b").exists()
    assert (workspace / "log" / "build_1").exists()
    outside = workspace.parent / "outside"
    assert all((outside / name / "keep").is_dir() for name in ("a", "b", "c"))
    assert (workspace / "install" / "setup.bash").is_file()  # the install scripts were refreshed
    assert (workspace / "src" / "a" / "package.xml").exists()


def test_base_select_and_ignore(workspace: Path) -> None:
    result = roc("work", "clean", "packages", "a", "--base-select", "build", "install", "--base-ignore", "install",
                 "-y", cwd=workspace)
    assert result.returncode == 0, result.stderr
    assert not (workspace / "build" / "a").exists() and (workspace / "install" / "a").exists()


def test_workspace_removes_the_bases_only(workspace: Path) -> None:
    result = roc("work", "clean", "workspace", "--base-ignore", "log", "-y", cwd=workspace)
    assert result.returncode == 0, result.stderr
    assert not (workspace / "build").exists() and not (workspace / "install").exists()
    assert (workspace / "log" / "build_1").exists() and (workspace / "src" / "a" / "package.xml").exists()
    assert all((workspace.parent / "outside" / name / "keep").is_dir() for name in ("a", "b", "c"))


def test_asks_first_and_refuses_without_a_terminal(workspace: Path) -> None:
    result = roc("work", "clean", "workspace", cwd=workspace)
    assert result.returncode == 2
    assert result.stdout.splitlines()[:2] == ["Paths:", "     build"]
    assert "pass -y/--yes" in result.stderr
    assert (workspace / "build" / "a").exists()


def test_refuses_a_base_that_holds_the_workspace(workspace: Path) -> None:
    result = roc("work", "clean", "workspace", "--build-base", ".", "-y", cwd=workspace)
    assert result.returncode == 2 and "refusing" in result.stderr
    assert (workspace / "src").exists()


def test_nothing_to_clean(workspace: Path) -> None:
    result = roc("work", "clean", "packages", "b", "--base-select", "log", cwd=workspace)
    assert (result.returncode, result.stdout) == (0, "No paths cleaned.\n")


def cli(*args: str, env: dict[str, str], cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN / "roc"), *args], env=env, cwd=cwd, capture_output=True, text=True, timeout=60,
                          stdin=subprocess.DEVNULL)


def _package(workspace: Path, name: str, depends: tuple[str, ...] = ()) -> None:
    add_cmake_package(workspace, name, f"cmake_minimum_required(VERSION 3.8)\nproject({name} NONE)\n", depends)


def test_clean_says_what_it_removed(tmp_path: Path) -> None:
    workspace = tmp_path / "ws"
    _package(workspace, "alpha")
    for base in ("build", "install"):
        (workspace / base / "alpha").mkdir(parents=True)
    cleaned = cli("work", "clean", "packages", "alpha", "-y", env=ros_env(), cwd=workspace)
    assert (cleaned.returncode, cleaned.stdout) == (0, "Removed:\n     build/alpha\n     install/alpha\n")
    assert not (workspace / "build" / "alpha").exists()
