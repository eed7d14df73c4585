"""A workspace built on roc's implicit underlay (nothing sourced: roc builds on its own venv's ROS 2
wheels) chains that underlay in its setup scripts, as colcon chains the underlays it was built on; and
roc's interface lookups see the same packages whichever verb asks."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.build import (
    BIN,
    REPO,
    add_cmake_package,
    colcon,
    copy_fixture,
    in_sourced_shell,
    roc,
    ros_env,
    sourced_values,
    without_own_underlay,
)

from roc.environment.chain import chained_underlays, prefix_operations
from roc.environment.dsv import Operation
from roc.shell.scripts import write_install_scripts

VENV = sys.prefix


def implicit_env() -> dict[str, str]:
    """A developer's shell with nothing ROS sourced (roc then builds on its own venv)."""
    return {k: v for k, v in ros_env().items() if k not in ("AMENT_PREFIX_PATH", "PYTHONPATH", "LD_LIBRARY_PATH")}


def interface_package(tmp_path: Path) -> Path:
    workspace = tmp_path / "ws"
    shutil.copytree(REPO / "workspaces" / "example" / "src" / "demo_interfaces", workspace / "src" / "demo_interfaces")
    return workspace


@pytest.mark.slow
@pytest.mark.colcon
def test_sourcing_a_workspace_built_on_the_implicit_underlay_brings_the_underlay_back(tmp_path: Path) -> None:
    ours = interface_package(tmp_path / "roc")
    built = roc("work", "build", cwd=ours, env=implicit_env())
    assert built.returncode == 0, built.stdout + built.stderr

    values = sourced_values(ours)  # a clean shell: only what the setup script sets
    assert values["AMENT_PREFIX_PATH"] == f"WS/install/demo_interfaces:{VENV}"
    assert f"{VENV}/lib/python3.{sys.version_info.minor}/site-packages" in values["PYTHONPATH"].split(":")
    assert f"{VENV}/lib" in values["LD_LIBRARY_PATH"].split(":")

    # the workspace's types, the underlay's, and a workspace type made of the underlay's
    looked_up = in_sourced_shell(ours, "roc interface show geometry_msgs/msg/Twist; echo ===; "
                                       "roc interface show demo_interfaces/msg/Reading; echo ===; "
                                       "roc interface packages")
    assert looked_up.returncode == 0, looked_up.stderr
    twist, reading, packages = looked_up.stdout.split("===\n")
    assert "Vector3  linear\n\tfloat64 x\n" in twist
    assert reading.startswith("# One sensor reading.\nstd_msgs/Header header\n\tbuiltin_interfaces/Time stamp\n")
    assert {"demo_interfaces", "geometry_msgs", "std_msgs"} <= set(packages.split())
    listed = in_sourced_shell(ours, "roc interface list")
    everything = roc("interface", "list", cwd=ours,
                     env=ros_env(AMENT_PREFIX_PATH=f"{ours}/install/demo_interfaces:{VENV}"))
    assert listed.stdout == everything.stdout and "demo_interfaces/msg/Reading" in listed.stdout

    # rebuilt in the sourced shell (the underlay is now named on AMENT_PREFIX_PATH): the same scripts
    setup = (ours / "install" / "setup.bash").read_text()
    rebuilt = in_sourced_shell(ours, "roc work build --packages-select demo_interfaces")
    assert rebuilt.returncode == 0, rebuilt.stdout + rebuilt.stderr
    assert (ours / "install" / "setup.bash").read_text() == setup

    # colcon, with the underlay sourced explicitly, chains nothing for a prefix without a local_setup
    # script: its environment is roc's less the underlay's entries
    theirs = interface_package(tmp_path / "colcon")
    result = colcon("build", cwd=theirs)
    assert result.returncode == 0, result.stdout + result.stderr
    colcon_values = sourced_values(theirs, strict=False)
    colcon_values["LD_LIBRARY_PATH"] = colcon_values["LD_LIBRARY_PATH"].rstrip(":")  # colcon's empty entry
    assert VENV not in colcon_values["AMENT_PREFIX_PATH"]
    assert without_own_underlay(values) == colcon_values


def test_interface_lookups_include_roc_s_own_environment_whatever_is_sourced(tmp_path: Path) -> None:
    """A workspace sourced by itself (AMENT_PREFIX_PATH without the venv): interface show finds the
    venv's types, as topic pub and echo (which import them) do."""
    install = tmp_path / "install" / "mine"
    (install / "share" / "ament_index" / "resource_index" / "packages").mkdir(parents=True)
    env = ros_env(AMENT_PREFIX_PATH=str(install))
    shown = roc("interface", "show", "geometry_msgs/msg/Twist", cwd=tmp_path, env=env)
    assert shown.returncode == 0 and "Vector3  linear" in shown.stdout, shown.stderr
    packages = roc("interface", "packages", cwd=tmp_path, env=env)
    assert "geometry_msgs" in packages.stdout.split()


# ---- which underlays the setup scripts chain ------------------------------------------------------

def _prefix(path: Path, local_setup: bool = False, packages: dict[str, str] | None = None) -> Path:
    """A fake install prefix: with a local_setup.sh, and/or ament packages with these package.dsv texts."""
    path.mkdir(parents=True)
    if local_setup:
        (path / "local_setup.sh").write_text("")
    for name, dsv in (packages or {}).items():
        index = path / "share" / "ament_index" / "resource_index" / "packages"
        index.mkdir(parents=True, exist_ok=True)
        (index / name).write_text("")
        (path / "share" / name).mkdir(parents=True)
        (path / "share" / name / "package.dsv").write_text(dsv)
    return path


def test_the_chain_is_colcon_s_plus_the_prefixes_colcon_cannot_chain(tmp_path: Path, monkeypatch) -> None:
    from colcon_core.prefix_path import get_chained_prefix_path

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    opt_ros = _prefix(tmp_path / "opt_ros", local_setup=True)  # an ament install: local_setup.*, no colcon marker
    isolated = _prefix(tmp_path / "under" / "install")  # a colcon install, isolated: its packages are listed
    (isolated / ".colcon_install_layout").write_text("isolated\n")
    package = _prefix(isolated / "core")
    wheels = _prefix(tmp_path / "venv", packages={  # ROS from wheels: no local_setup script
        "a": "prepend-non-duplicate;AMENT_PREFIX_PATH;\nprepend-non-duplicate;PYTHONPATH;lib/site\n",
        "b": "prepend-non-duplicate;AMENT_PREFIX_PATH;\nsource;share/b/hook.sh\n"})
    bare = _prefix(tmp_path / "empty")  # nothing to chain
    base = tmp_path / "ws" / "install"
    environ = {"COLCON_PREFIX_PATH": f"{isolated}:{tmp_path / 'gone'}",
               "AMENT_PREFIX_PATH": os.pathsep.join(map(str, [base / "x", package, wheels, opt_ros, bare, wheels]))}
    _prefix(base / "x")
    (base / ".colcon_install_layout").write_text("isolated\n")

    chain = chained_underlays(environ, base)
    for name, value in environ.items():
        monkeypatch.setenv(name, value)
    theirs = [str(p) for p in get_chained_prefix_path(skip=str(base))]
    assert [u.prefix for u in chain if not u.operations] == theirs == [str(isolated), str(opt_ros)]
    assert [(u.prefix, u.operations) for u in chain if u.operations] == [(str(wheels), (
        Operation("prepend-non-duplicate", "AMENT_PREFIX_PATH", ("",)),
        Operation("prepend-non-duplicate", "PYTHONPATH", ("lib/site",))))]
    assert [u.prefix for u in chain] == [str(isolated), str(wheels), str(opt_ros)]


def test_a_prefix_s_hooks_are_read_again_when_its_packages_change(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    wheels = _prefix(tmp_path / "venv", packages={"a": "prepend-non-duplicate;PATH;bin\n"})
    assert prefix_operations(wheels) == (Operation("prepend-non-duplicate", "PATH", ("bin",)),)
    assert list((tmp_path / "cache" / "roc").rglob("*.json"))  # remembered
    (wheels / "share" / "ament_index" / "resource_index" / "packages" / "a").unlink()
    assert prefix_operations(wheels) == ()


@pytest.mark.parametrize("shell", ["sh", "bash", "zsh"])
def test_a_baked_underlay_s_path_survives_quoting(tmp_path: Path, monkeypatch, shell: str) -> None:
    if shutil.which(shell) is None:
        pytest.skip(f"{shell} is not installed")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    odd = _prefix(tmp_path / "it's $HOME `x` \"q\" ;", packages={"a": "prepend-non-duplicate;AMENT_PREFIX_PATH;\n"})
    base = tmp_path / "install"
    base.mkdir()
    write_install_scripts(base, [], False, chained_underlays({"AMENT_PREFIX_PATH": str(odd)}, base))
    sourced = subprocess.run([shell, "-c", '. "$0"; printf %s "$AMENT_PREFIX_PATH"', str(base / f"setup.{shell}")],
                             env={"PATH": "/usr/bin:/bin"}, capture_output=True, text=True, timeout=30)
    assert (sourced.returncode, sourced.stdout, sourced.stderr) == (0, str(odd), "")


def _underlay(tmp_path: Path) -> Path:
    """An installed underlay with 'pyp' (as in build_small) and 'user', which needs pyp at run time."""
    prefix = tmp_path / "underlay"
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    for name in ("pyp", "user", "leaf"):
        (index / name).write_text("")
    (prefix / "share" / "user").mkdir()
    (prefix / "share" / "user" / "package.xml").write_text(
        '<package format="3"><name>user</name><version>1.0.0</version><description>d</description>'
        '<maintainer email="m@example.com">M</maintainer><license>MIT</license>'
        "<exec_depend>pyp</exec_depend></package>\n")
    return prefix


@pytest.mark.slow
def test_overriding_an_underlay_package_warns_unless_allowed(tmp_path: Path) -> None:
    workspace = copy_fixture("build_small", tmp_path / "ws")
    prefix = _underlay(tmp_path)
    env = ros_env(AMENT_PREFIX_PATH=f"{prefix}{os.pathsep}{sys.prefix}")
    warned = roc("work", "build", "--packages-select", "pyp", cwd=workspace, env=env)
    assert warned.returncode == 0, warned.stderr
    assert "roc: warning: some selected packages are already installed in an underlay workspace" in warned.stderr
    assert f"'pyp' is in: {prefix}" in warned.stderr
    assert "--allow-overriding pyp" in warned.stderr
    allowed = roc("work", "build", "--packages-select", "pyp", "--allow-overriding", "pyp", "nothere",
                  cwd=workspace, env=env)
    assert allowed.returncode == 0, allowed.stderr
    assert "underlay" not in allowed.stderr
    assert "--allow-overriding: ignoring unknown package 'nothere'" in allowed.stderr


def test_overriding_an_unused_underlay_package_does_not_warn(tmp_path: Path) -> None:
    from roc.workspace.underlay import overridden_packages

    prefix = _underlay(tmp_path)
    env = {"AMENT_PREFIX_PATH": str(prefix)}
    assert overridden_packages({"leaf"}, tmp_path / "install", [], env) == {}
    assert overridden_packages({"pyp", "leaf"}, tmp_path / "install", [], env) == {"pyp": [prefix]}
    # once this workspace builds 'user' too, nothing in the underlay uses the old pyp
    assert overridden_packages({"pyp", "user"}, tmp_path / "install", [], env) == {}
    # an underlay that is this workspace's own install base is not an underlay
    assert overridden_packages({"pyp"}, prefix, [], env) == {}


def cli(*args: str, env: dict[str, str], cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN / "roc"), *args], env=env, cwd=cwd, capture_output=True, text=True, timeout=60,
                          stdin=subprocess.DEVNULL)


def _package(workspace: Path, name: str, depends: tuple[str, ...] = ()) -> None:
    add_cmake_package(workspace, name, f"cmake_minimum_required(VERSION 3.8)\nproject({name} NONE)\n", depends)


def test_a_dependency_found_nowhere_is_warned_about_once_with_the_closest_name(tmp_path: Path) -> None:
    workspace = tmp_path / "ws"
    _package(workspace, "alpha", ("std_msg", "eigen", "python3-numpy", "beta", "std_msgs"))
    _package(workspace, "beta", ("std_msg",))
    built = cli("work", "build", env=ros_env(), cwd=workspace)
    assert built.returncode == 0, built.stderr
    assert built.stderr.splitlines() == [
        "roc: warning: 'eigen', a dependency of alpha, is in neither the workspace nor an underlay; a typo? "
        "(a system dependency that rosdep installs is fine)",
        "roc: warning: 'std_msg', a dependency of alpha, beta, is in neither the workspace nor an underlay; "
        "did you mean 'std_msgs'?"]
    only_beta = cli("work", "build", "--packages-select", "alpha", env=ros_env(), cwd=workspace)
    assert "'std_msg', a dependency of alpha, is" in only_beta.stderr


@pytest.mark.slow
def test_a_missing_dependency_is_warned_about_once_until_a_manifest_of_the_workspace_changes(tmp_path: Path) -> None:
    workspace = tmp_path / "ws"
    _package(workspace, "alpha", ("eigen",))
    _package(workspace, "beta")
    warning = "roc: warning: 'eigen', a dependency of alpha, is in neither the workspace nor an underlay"
    assert warning in cli("work", "build", env=ros_env(), cwd=workspace).stderr
    again = cli("work", "build", env=ros_env(), cwd=workspace)  # a no-op
    assert again.returncode == 0 and again.stderr == "", again.stderr
    manifest = workspace / "src" / "beta" / "package.xml"
    manifest.write_text(manifest.read_text().replace("0.0.1", "0.0.2"))
    assert warning in cli("work", "build", env=ros_env(), cwd=workspace).stderr


@pytest.mark.slow
def test_a_package_is_never_suggested_as_its_own_missing_dependency(tmp_path: Path) -> None:
    workspace = tmp_path / "ws"
    _package(workspace, "lifecycle_py", ("lifecycle",))  # 0.86 alike: the closest name, but its own
    built = cli("work", "build", env=ros_env(), cwd=workspace)
    assert built.stderr.splitlines() == [
        "roc: warning: 'lifecycle', a dependency of lifecycle_py, is in neither the workspace nor an underlay; "
        "a typo? (a system dependency that rosdep installs is fine)"]


@pytest.mark.slow
def test_missing_test_dependencies_are_one_note_and_none_on_a_build_without_tests(tmp_path: Path) -> None:
    workspace = tmp_path / "ws"
    lint_dependencies = ("ament_lint_auto", "ament_lint_common")
    add_cmake_package(workspace, "alpha", "cmake_minimum_required(VERSION 3.8)\nproject(alpha NONE)\n",
                      test_depends=(*lint_dependencies, "lifecycle"))
    add_cmake_package(workspace, "beta", "cmake_minimum_required(VERSION 3.8)\nproject(beta NONE)\n",
                      test_depends=lint_dependencies)
    without_tests = cli("work", "build", "--cmake-args", "-DBUILD_TESTING=OFF", env=ros_env(), cwd=workspace)
    assert without_tests.returncode == 0 and without_tests.stderr == "", without_tests.stderr
    built = cli("work", "build", env=ros_env(), cwd=workspace)
    assert built.stderr.splitlines() == [
        "roc: note: 3 test dependencies in neither the workspace nor an underlay, needed only to build and run the "
        "tests (--cmake-args -DBUILD_TESTING=OFF builds without them): ament_lint_auto (of alpha, beta), "
        "ament_lint_common (of alpha, beta), lifecycle (of alpha)"]


def test_a_build_without_tests_is_told_by_any_of_cmakes_false_values_for_build_testing(tmp_path: Path) -> None:
    from roc.buildtypes.context import BuildOptions

    def builds_tests(*cmake_args: str, **per_package: tuple[str, ...]) -> bool:
        return BuildOptions(tmp_path, tmp_path, cmake_args=cmake_args, package_cmake_args=per_package).builds_tests("a")

    assert builds_tests() and builds_tests("-DBUILD_TESTING=ON") and builds_tests("-DBUILD_TESTING_X=OFF")
    assert not builds_tests("-DBUILD_TESTING=OFF") and not builds_tests("-DBUILD_TESTING:BOOL=0")
    assert not builds_tests("-DBUILD_TESTING=no") and not builds_tests(a=("-DBUILD_TESTING=FALSE",))
    assert builds_tests("-DBUILD_TESTING=OFF", a=("-DBUILD_TESTING=ON",))  # the package's own arguments come last
