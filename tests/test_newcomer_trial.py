"""Fixes of issue 33 (what a newcomer trial of the whole tool found) that need no ROS graph: the
set-up's system changes are opt-in, the oracles' skips are summarised, exit codes and hints, and the
messages of clean, param set and the dependency check."""

from __future__ import annotations

import contextlib
import io
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from build_helpers import BIN, REPO, add_cmake_package, ros_env
from graph_helpers import graph_env, stop_daemon

from roc.cli.commands import COMMANDS, verbs
from roc.commands.topic.pub import waiting_text
from roc.ros.types import UnknownTypeError, resolve_type


def cli(*args: str, env: dict[str, str], cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN / "roc"), *args], env=env, cwd=cwd, capture_output=True, text=True, timeout=60,
                          stdin=subprocess.DEVNULL)

# ---- scripts/setup.sh changes the system only when asked -----------------------------------------

# what the set-up runs, without zsh, fish, tmux, ccache and sshd
TOOLS = ("bash", "dirname", "sha256sum", "cut", "cat", "flock", "grep", "env", "rm")


def _setup_without_shells(tmp_path: Path, **extra: str) -> tuple[subprocess.CompletedProcess, str]:
    """Run a copy of scripts/setup.sh all through (ROC_SETUP_FORCE=1) as root, on a PATH without zsh and
    fish, in a checkout whose venv's Python does nothing, with an apt-get that records its arguments;
    returns the run and what apt-get was asked."""
    checkout = tmp_path / "checkout"
    (checkout / "scripts").mkdir(parents=True)
    shutil.copy(REPO / "scripts" / "setup.sh", checkout / "scripts")
    fake = tmp_path / "bin"
    fake.mkdir()
    for tool in TOOLS:
        os.symlink(shutil.which(tool), fake / tool)
    calls = tmp_path / "apt-get.calls"
    scripts = {fake / "apt-get": f'echo "$*" >> {calls}', fake / "id": "echo 0"}
    scripts.update({checkout / ".venv" / "bin" / name: "exit 0" for name in ("python", "roc", "colcon")})
    for path, body in scripts.items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(f"#!/bin/sh\n{body}\n")
        path.chmod(0o755)
    env = {"PATH": str(fake), "HOME": str(tmp_path), "TMPDIR": str(tmp_path), "ROC_SETUP_FORCE": "1", **extra}
    run = subprocess.run(["bash", str(checkout / "scripts" / "setup.sh")], env=env, capture_output=True, text=True,
                         timeout=120)
    return run, calls.read_text() if calls.exists() else ""


def test_the_set_up_installs_no_system_package_unless_asked(tmp_path: Path) -> None:
    run, asked = _setup_without_shells(tmp_path)
    assert run.returncode == 0, run.stderr
    assert asked == ""
    assert "setup: zsh fish tmux ccache openssh-server not installed: their tests will be skipped (ROC_SETUP_TEST_TOOLS=1 installs them)" in run.stderr


def test_roc_setup_test_tools_installs_zsh_fish_tmux_and_ccache_and_says_so(tmp_path: Path) -> None:
    run, asked = _setup_without_shells(tmp_path, ROC_SETUP_TEST_TOOLS="1")
    assert run.returncode == 0, run.stderr
    assert "setup: ROC_SETUP_TEST_TOOLS=1: installing zsh fish tmux ccache openssh-server with apt-get" in run.stderr
    assert asked.splitlines() == ["update -qq", "install -y -qq zsh fish tmux ccache openssh-server"]


def test_ci_opts_in_and_the_set_up_says_what_the_option_does() -> None:
    assert "export ROC_SETUP_TEST_TOOLS=1" in (REPO / ".ci" / "run").read_text()
    header = (REPO / "scripts" / "setup.sh").read_text().split("set -euo pipefail")[0]
    assert "ROC_SETUP_TEST_TOOLS=1  also install zsh, fish, tmux, ccache and openssh-server" in header


# ---- tests skipped for a missing oracle are summed up; CI fails instead ------------------------------

PROBE_TESTS = '''
import pytest
from oracles import SHARED, require_oracle

@pytest.mark.parametrize("n", range(3))
def test_needs_the_cli(n):
    require_oracle("ros2 CLI", SHARED / "oracles" / "cli.sh")

@pytest.fixture(scope="module")
def reference():
    return require_oracle("reference", SHARED / "reference")

def test_needs_a_reference(reference):
    pass

def test_needs_nothing():
    pass
'''


def _run_probe_suite(tmp_path: Path, shared: Path, workers: int = 0, **extra: str) -> subprocess.CompletedProcess:
    """pytest (on ``workers`` pytest-xdist workers, as scripts/test.sh runs it) on a tiny suite with
    tests/conftest.py and tests/oracles.py, the oracles looked up in ``shared``."""
    suite = tmp_path / "suite"
    suite.mkdir()
    for name in ("conftest.py", "oracles.py"):
        shutil.copy(REPO / "tests" / name, suite)
    (suite / "test_probe.py").write_text(PROBE_TESTS)
    env = {k: v for k, v in os.environ.items() if k not in ("CI", "PYTEST_ADDOPTS")}
    env.update(ROC_TEST_SHARED=str(shared), **extra)
    command = [sys.executable, "-m", "pytest", "-n", str(workers), "-p", "no:cacheprovider", "-q", str(suite)]
    return subprocess.run(command, cwd=suite, env=env, capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("workers", [0, pytest.param(2, marks=pytest.mark.slow)])
def test_skips_for_missing_oracles_are_summed_up_one_line_per_reason(tmp_path: Path, workers: int) -> None:
    missing = tmp_path / "no-shared"
    run = _run_probe_suite(tmp_path, missing, workers)
    assert run.returncode == 0, run.stdout + run.stderr
    summary = run.stdout.split("missing oracles")[1].splitlines()[1:3]
    assert summary == [f"3 tests skipped: oracle ros2 CLI not found at {missing}/oracles/cli.sh",
                       f"1 test skipped: oracle reference not found at {missing}/reference"]
    assert "1 passed, 4 skipped" in run.stdout


def test_in_ci_a_missing_oracle_fails_the_run(tmp_path: Path) -> None:
    run = _run_probe_suite(tmp_path, tmp_path / "no-shared", CI="true")
    assert run.returncode == 1
    assert "3 failed, 1 passed, 1 error" in run.stdout and "missing oracles" not in run.stdout
    assert "CI must have every oracle" in run.stdout


def test_with_the_oracles_nothing_is_skipped(tmp_path: Path) -> None:
    shared = tmp_path / "shared"
    (shared / "oracles").mkdir(parents=True)
    (shared / "oracles" / "cli.sh").write_text("")
    (shared / "reference").mkdir()
    run = _run_probe_suite(tmp_path, shared, CI="true")
    assert run.returncode == 0 and "5 passed" in run.stdout, run.stdout


@pytest.fixture
def runtime(tmp_path_factory) -> Path:
    """A runtime directory short enough for the daemon's socket (a long one falls back to a shared one)."""
    return tmp_path_factory.mktemp("rt")


# ---- exit codes and hints -------------------------------------------------------------------------

@pytest.mark.parametrize("verb", [
    ["topic", "pub", "/x"], *(pytest.param(verb, marks=pytest.mark.slow) for verb in [
        ["interface", "show"], ["topic", "echo", "/x"], ["interface", "proto"], ["service", "call", "/x"],
        ["action", "send_goal", "/x"]])],
    ids=lambda verb: " ".join(verb[:2]))
def test_every_verb_exits_1_for_a_type_not_installed_and_2_for_a_malformed_name(runtime: Path, verb) -> None:
    kind = {"service": "srv", "action": "action"}.get(verb[0], "msg")
    extra = ["{}"] if verb[0] == "action" else []
    env = graph_env(19, runtime)
    unknown = cli(*verb, f"foo_{kind}s/{kind}/Bar", *extra, env=env)
    assert (unknown.returncode, unknown.stdout, len(unknown.stderr.splitlines())) == (1, "", 1), unknown.stderr
    malformed = cli(*verb, "Bar", *extra, env=env)
    assert (malformed.returncode, malformed.stdout, len(malformed.stderr.splitlines())) == (2, "", 1), malformed.stderr
    status = json.loads(cli("daemon", "status", "--format", "json", env=env).stdout)
    if verb[:2] == ["interface", "show"]:  # a message type not installed here is asked of the graph's nodes
        assert status["running"] is True
        stop_daemon(env)
    else:
        assert status["running"] is False  # decided before any daemon was asked


def test_only_close_interface_package_names_are_suggested() -> None:
    with pytest.raises(UnknownTypeError) as far:
        resolve_type("foo_msgs/msg/Bar")
    assert "did you mean" not in str(far.value)
    with pytest.raises(UnknownTypeError) as near:
        resolve_type("std_msg/msg/String")
    assert "(did you mean 'std_msgs'?)" in str(near.value)


@pytest.mark.parametrize("words, hint", [
    (["work", "buld"], "unknown command 'buld'; did you mean 'build'? (see 'roc work --help')"),
    (["wrk", "build"], "unknown command 'wrk'; did you mean 'work'? (see 'roc --help')"),
    (["work", "clean", "pakages"], "unknown command 'pakages'; did you mean 'packages'? (see 'roc work clean --help')"),
    (["topic", "xyzzy"], "unknown command 'xyzzy'; choose from list, info, type, find, echo, pub, hz, bw, delay "
                         "(see 'roc topic --help')"),
])
def test_a_mistyped_command_gets_the_closest_name(tmp_path: Path, words: list[str], hint: str) -> None:
    result = cli(*words, env=ros_env(), cwd=tmp_path)
    group = hint.rsplit("(see '", 1)[1].split(" --help")[0]  # the group's parser reports it, as argparse does
    assert (result.returncode, result.stdout, result.stderr) == (2, "", f"{group}: error: {hint}\n")


def _help_of(name: str, parent_help: str) -> str:
    """A command's help text in its parent's --help (on the next line when the name is long)."""
    lines = parent_help.splitlines()
    index = next(i for i, line in enumerate(lines) if line.split()[:1] == [name])
    return " ".join((lines[index] + " " + lines[index + 1] if len(lines[index].split()) == 1 else lines[index])
                    .split())


def _help(*words: str) -> str:
    """``roc WORDS --help``, in this process."""
    from roc.cli.main import main

    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit):
        main([*words, "--help"])
    return out.getvalue()


def test_every_group_s_help_lists_all_its_commands(monkeypatch) -> None:
    monkeypatch.setenv("COLUMNS", "1000")  # no wrapped lines
    groups = [path for path, _, module, _ in COMMANDS if module is None]
    assert ("interface",) in groups
    for group in groups:
        text = _help_of(group[-1], _help(*group[:-1]))
        assert text.endswith(": " + ", ".join(verbs(group))), text
    assert _help_of("interface", _help()).endswith(": list, packages, package, show, proto")


def test_pub_says_once_how_to_stop_waiting_instead_of_repeating_its_waiting_line() -> None:
    lines = [waiting_text(count, 1) for count in range(1, 9)]
    assert lines[:4] == ["Waiting for at least 1 matching subscription(s)...\n"] * 4
    assert lines[4] == ("Still waiting for 1 matching subscription(s) after 4 s, until they appear: Ctrl+C stops, "
                        "'-w 0' publishes without waiting, '--max-wait-time-secs SECONDS' gives up\n")
    assert lines[5:] == ["", "", ""]


# ---- roc graph check's output -----------------------------------------------------------------------

def test_the_summary_separates_names_that_have_spaces() -> None:
    from roc.engine.events import RunFinished, TaskFailed, TaskStarted
    from roc.handlers.console import ConsoleHandler

    out = io.StringIO()
    console = ConsoleHandler(out, kind="probe", noun="probe", cached_label="")
    for name in ("topic /imu", "node /ghost_node", "parameter /motor_controller max_speed"):
        console(TaskStarted(name, "probe"))
        console(TaskFailed(name, "probe", reason="fail: no"))
    console(RunFinished("", "probe"))
    assert ("  3 probes failed: node /ghost_node, parameter /motor_controller max_speed, topic /imu\n"
            in out.getvalue())
    packages = io.StringIO()
    console = ConsoleHandler(packages)
    for name in ("b", "a"):
        console(TaskFailed(name, reason="failed"))
    console(RunFinished(""))
    assert "  2 packages failed: a b\n" in packages.getvalue()  # as colcon


def test_the_last_json_event_carries_the_run_s_kind() -> None:
    from roc.engine.executor import execute
    from roc.engine.ready import Task
    from roc.handlers.logs import JsonEventsHandler

    out = io.StringIO()
    execute([Task(name="node /a", dependencies=set(), action=lambda context: None, kind="probe")],
            [JsonEventsHandler(out)], 0, kind="probe")
    last = json.loads(out.getvalue().splitlines()[-1])
    assert (last["event"], last["kind"]) == ("RunFinished", "probe")


def test_probe_values_are_printed_as_yaml() -> None:
    from roc.check.probes import _mismatches
    from roc.render import to_yaml_line

    assert to_yaml_line({"success": True, "message": ""}) == "{success: true, message: ''}"
    assert [to_yaml_line(v) for v in (1.5, "demo_bot", [1.0, 0.1], None)] == ["1.5", "demo_bot", "[1.0, 0.1]", "null"]
    assert _mismatches({"success": True, "pose": {"x": 1}}, {"success": False, "pose": {"x": 2}}) == [
        "success: false, expected true", "pose.x: 2, expected 1"]


# ---- param set, clean, missing dependencies, daemon status --------------------------------------------

def test_param_set_names_an_undeclared_parameter() -> None:
    from roc.commands.param.set import named_reason

    assert named_reason("max_sped", "Invalid access to undeclared parameter(s): []") == (
        "Invalid access to undeclared parameter(s): max_sped")
    assert named_reason("x", "Wrong parameter type") == "Wrong parameter type"


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


def test_daemon_status_says_which_daemon(runtime: Path) -> None:
    from roc.commands.daemon.status import status_lines

    running = {"running": True, "pid": 42, "socket": "/run/roc/daemon-1.sock",
               "environment": {"ROS_DOMAIN_ID": "", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}}
    assert status_lines(running) == ["The daemon is running", "  pid: 42",
                                     "  discovery environment: ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST",
                                     "  socket: /run/roc/daemon-1.sock"]
    env = graph_env(19, runtime)
    stopped = json.loads(cli("daemon", "status", "--format", "json", env=env).stdout)
    assert stopped["running"] is False and stopped["environment"]["ROS_DOMAIN_ID"] == env["ROS_DOMAIN_ID"]
    assert stopped["socket"].startswith(f"{runtime}/roc/daemon-") and stopped["socket"].endswith(".sock")
