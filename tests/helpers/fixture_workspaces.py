"""Helpers for the workspace tests: copies of the fixture workspaces, and running roc and the real
colcon (the test oracle) on them in one and the same environment.

The fixtures live inside the roc repository, so every test works on a copy in a temporary directory:
roc's workspace-root search would otherwise walk up into the repository.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
FIXTURES = REPO / "workspaces" / "fixtures"
ORACLE_SETUPTOOLS = Path(sys.prefix) / "oracle-setuptools"  # installed by scripts/setup.sh
GOOD_FIXTURES = ("discovery", "formats", "cmake", "python", "colcon_pkg", "selection")
# colcon reads conditions from the environment only; roc defaults ROS_VERSION and ROS_PYTHON_VERSION
# (a deliberate difference), so both run with them set.
ROS_ENVIRONMENT = {"ROS_VERSION": "2", "ROS_PYTHON_VERSION": "3", "ROS_DISTRO": "jazzy"}


@dataclass
class Result:
    returncode: int
    stdout: str
    stderr: str = ""


def tool_environment(**overrides: str | None) -> dict[str, str]:
    """The environment both tools run in: no user configuration of colcon, no ROS variables but ours
    (``NAME=None`` removes a variable)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("COLCON_", "ROS_", "AMENT_", "ROC_"))}
    env.update(ROS_ENVIRONMENT)
    env["COLCON_HOME"] = os.devnull  # no ~/.colcon/defaults.yaml
    env["PYTHONWARNINGS"] = "ignore"
    for name, value in overrides.items():
        if value is None:
            env.pop(name, None)
        else:
            env[name] = value
    return env


def run_roc(*args: str, cwd: Path, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    """roc as a user runs it: a new process, its exit code and both streams."""
    return subprocess.run(
        [sys.executable, "-m", "roc", *args], cwd=cwd, env=env if env is not None else tool_environment(),
        capture_output=True, text=True, timeout=60,
    )


def run_roc_inprocess(argv: list[str], cwd: Path, env: dict[str, str]) -> Result:
    """roc's ``main()`` in this process (milliseconds instead of a start-up each), with ``cwd`` and
    ``env`` in force while it runs."""
    from roc.cli.main import main

    saved_cwd, saved_env = os.getcwd(), dict(os.environ)
    out, err = io.StringIO(), io.StringIO()
    try:
        os.chdir(cwd)
        os.environ.clear()
        os.environ.update(env)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as error:  # argparse usage errors and --help
                code = error.code if isinstance(error.code, int) else 1
    finally:
        os.chdir(saved_cwd)
        os.environ.clear()
        os.environ.update(saved_env)
    return Result(code, out.getvalue(), err.getvalue())


def colcon_available() -> bool:
    return all(importlib.util.find_spec(m) is not None for m in ("colcon_core", "colcon_ros", "colcon_cmake"))


# Runs several colcon commands in one interpreter: colcon's start-up (loading its extensions) is paid
# once per workspace instead of once per command.
_COLCON_BATCH = """
import contextlib, io, json, sys
from colcon_core.command import main
results = []
for argv in json.loads(sys.argv[1]):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        try:
            code = main(argv=["--log-base", "/dev/null", *argv])
        except SystemExit as error:
            code = error.code
    if not isinstance(code, int):
        code = 0 if code is None else 1
    results.append([code, out.getvalue()])
sys.__stdout__.write(json.dumps(results))
"""


def run_colcon_batch(commands: list[list[str]], cwd: Path, env: dict[str, str]) -> list[Result]:
    """The exit code and stdout of ``colcon <command>`` for each command, run in ``cwd``, with the
    setuptools of Jazzy's platform (72+ drops ``tests_require``, which colcon then does not report)."""
    env = {**env, "PYTHONPATH": os.pathsep.join(filter(None, [str(ORACLE_SETUPTOOLS), env.get("PYTHONPATH")]))}
    process = subprocess.run(
        [sys.executable, "-c", _COLCON_BATCH, json.dumps(commands)], cwd=cwd, env=env,
        capture_output=True, text=True, timeout=300,
    )
    assert process.returncode == 0, process.stderr
    return [Result(code, stdout) for code, stdout in json.loads(process.stdout)]


def normalize(command: list[str], output: str) -> list[str]:
    """Output lines made comparable: colcon's info prints a Python function object that roc has no
    counterpart of, and the order of colcon's DOT edges (and of cluster members) follows Python set
    order, so those are sorted; nodes outside clusters keep their order."""
    lines = [line for line in output.splitlines() if "get_python_setup_options: <function" not in line]
    if "--dot-cluster" in command:
        return sorted(lines)
    if "--dot" in command:
        return [line for line in lines if " -> " not in line] + sorted(line for line in lines if " -> " in line)
    return lines
