"""The installed ``roc`` command (bin/roc): one Python start, with the environment the ROS wheels'
bootstrapper would have set, so that children and ROS libraries see the same as before."""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

from helpers.build import REPO

LAUNCHER = REPO / "bin" / "roc"
BOOT_FLAG = "_ROS_WHEELS_BOOTSTRAP_COMPLETE"
FAKE_PYTHON = """#!/bin/sh
printf 'LD_LIBRARY_PATH=%s\\n' "${LD_LIBRARY_PATH-<unset>}"
printf 'FLAG=%s\\n' "${_ROS_WHEELS_BOOTSTRAP_COMPLETE-<unset>}"
shift 2  # -c CODE
for argument in "$@"; do printf 'ARG=%s\\n' "$argument"; done
"""


def plain_environment(**extra: str) -> dict[str, str]:
    """This environment as it is before anything bootstrapped it."""
    env = {k: v for k, v in os.environ.items() if k not in (BOOT_FLAG, "LD_LIBRARY_PATH")}
    env.update(extra)
    return env


def fake_venv(tmp_path: Path, with_bootstrapper: bool = True) -> Path:
    """A venv's layout whose python prints its environment and arguments."""
    bin_dir = tmp_path / "venv" / "bin"
    bin_dir.mkdir(parents=True)
    shutil.copy2(LAUNCHER, bin_dir / "roc")
    (bin_dir / "python").write_text(FAKE_PYTHON)
    (bin_dir / "python").chmod(0o755)
    site = tmp_path / "venv" / "lib" / "python3.11" / "site-packages"
    (site / "ros_rclpy.libs").mkdir(parents=True)
    (site / "ros_rcl.libs").mkdir()
    if with_bootstrapper:
        (site / "ros_wheels_bootstrapper.pth").write_text("import ros_wheels_bootstrapper\n")
    return tmp_path / "venv"


def run(command: list[str], env: dict[str, str]) -> dict[str, list[str]]:
    result = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
    seen: dict[str, list[str]] = {}
    for line in result.stdout.splitlines():
        key, _, value = line.partition("=")
        seen.setdefault(key, []).append(value)
    return seen


def test_sets_the_bootstrappers_library_path_and_flag_and_passes_arguments_untouched(tmp_path):
    venv = fake_venv(tmp_path)
    site = venv / "lib" / "python3.11" / "site-packages"
    seen = run([str(venv / "bin" / "roc"), "topic", "echo", "a b", "--x=*"],
               plain_environment(LD_LIBRARY_PATH="/opt/mine"))
    assert seen["LD_LIBRARY_PATH"] == [f"{venv}/lib:{site}/ros_rcl.libs:{site}/ros_rclpy.libs:/opt/mine"]
    assert seen["FLAG"] == ["1"]
    assert seen["ARG"] == ["topic", "echo", "a b", "--x=*"]


def test_keeps_the_order_of_library_folders_a_sourced_workspace_listed(tmp_path):
    venv = fake_venv(tmp_path)
    site = venv / "lib" / "python3.11" / "site-packages"
    # a workspace's setup script put its own libraries before the venv's, and one ros_*.libs folder
    sourced = f"/ws/install/rclcpp/lib:{venv}/lib:{site}/ros_rcl.libs"
    seen = run([str(venv / "bin" / "roc"), "--version"], plain_environment(LD_LIBRARY_PATH=sourced))
    assert seen["LD_LIBRARY_PATH"] == [f"{site}/ros_rclpy.libs:{sourced}"]
    assert seen["FLAG"] == ["1"]


def test_changes_nothing_where_no_bootstrapper_is_installed_or_it_already_ran(tmp_path):
    venv = fake_venv(tmp_path, with_bootstrapper=False)
    assert run([str(venv / "bin" / "roc")], plain_environment()) == {"LD_LIBRARY_PATH": ["<unset>"],
                                                                      "FLAG": ["<unset>"]}
    shutil.copy2(LAUNCHER, venv / "bin" / "roc")
    (venv / "lib" / "python3.11" / "site-packages" / "ros_wheels_bootstrapper.pth").write_text("")
    booted = plain_environment(LD_LIBRARY_PATH="/already", **{BOOT_FLAG: "1"})
    assert run([str(venv / "bin" / "roc")], booted) == {"LD_LIBRARY_PATH": ["/already"], "FLAG": ["1"]}


def test_finds_its_venv_through_a_symbolic_link(tmp_path):
    venv = fake_venv(tmp_path)
    link_dir = tmp_path / "elsewhere"
    link_dir.mkdir()
    (link_dir / "roc").symlink_to(os.path.relpath(venv / "bin" / "roc", link_dir))
    seen = run([str(link_dir / "roc"), "--version"], plain_environment())
    assert seen["LD_LIBRARY_PATH"][0].startswith(f"{link_dir}/../venv/lib:")
    assert seen["ARG"] == ["--version"]


def installed_roc() -> Path:
    """The roc scripts/setup.sh installed beside the test's Python."""
    command = Path(sys.executable).parent / "roc"
    assert command.read_bytes() == LAUNCHER.read_bytes(), f"{command} is not bin/roc: run scripts/setup.sh"
    return command


def python_starts(command: list[str], cwd: Path) -> int:
    """How many Python interpreters ``command`` started (each prints its ``encodings`` import first)."""
    result = subprocess.run(command, cwd=cwd, env=plain_environment(PYTHONPROFILEIMPORTTIME="1"),
                            capture_output=True, text=True, check=True)
    assert result.stdout.startswith("roc ")
    return sum(line.endswith("| encodings") for line in result.stderr.splitlines())


def test_the_installed_command_starts_python_once_where_python_m_roc_starts_it_twice(tmp_path):
    roc = installed_roc()
    assert python_starts([sys.executable, "-m", "roc", "--version"], tmp_path) == 2
    (tmp_path / "roc").mkdir()  # a folder named roc in the working directory is not imported
    assert python_starts([str(roc), "--version"], tmp_path) == 1


def test_what_the_installed_command_starts_loads_the_ros_libraries(tmp_path):
    """A process roc starts inherits the launcher's environment, so it does not re-execute itself,
    and rclpy, whose libraries only that LD_LIBRARY_PATH finds, starts in it."""
    roc = installed_roc()
    code = ("import os, rclpy; rclpy.init(); rclpy.shutdown(); "
            "print(os.environ['_ROS_WHEELS_BOOTSTRAP_COMPLETE'], os.environ['LD_LIBRARY_PATH'])")
    result = subprocess.run([str(roc), "run", "--prefix", f"{shlex.quote(sys.executable)} -c {shlex.quote(code)}",
                             "rosidl_adapter", "msg2idl.py"], cwd=tmp_path, env=plain_environment(),
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    flag, library_path = result.stdout.split()
    assert flag == "1"
    assert library_path.split(":")[0] == str(roc.parent.parent / "lib")
