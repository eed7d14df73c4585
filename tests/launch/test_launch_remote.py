"""roc launch of a roc.toml system with a process on another host (``host = "robot"``: an sshd this module
starts on 127.0.0.1, roc_launch_demo sourced there from the test's install): it starts beside a local one,
both are in the graph, its output is relayed with the host in the prefix, and --explain says exactly what
ran (/proc); when roc is killed, or its SSH connection is killed or cut, the remote side stops the process
within the documented bound (roc/launch/remote_guard.py); an unreachable host and a missing executable
fail before anything starts."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import time
from pathlib import Path

import pytest
from helpers.graph import roc, stop_daemon
from helpers.launch import demo_env, kill_leftovers, roc_launch, wait_for_nodes, wait_until
from helpers.proc import as_proc_shows, proc_argv, proc_environ
from helpers.ssh import REMOTE, alive, ancestors, comm, ssh_server, sshd_session, write_pair

from roc.launch.guard import GRACE_SECONDS
from roc.launch.remote_guard import SILENCE_SECONDS

pytestmark = pytest.mark.slow
LOAD_MARGIN = 15.0  # a loaded CI machine: seconds beyond the documented bound before the test fails
@pytest.fixture(scope="module")
def remote(tmp_path_factory, launch_demo_prefix):
    """The test's domain, with roc_launch_demo sourced, and an sshd whose login sources it (its setup)."""
    prefix = launch_demo_prefix
    with ssh_server(tmp_path_factory.mktemp("ssh")) as server:
        env = demo_env(54, tmp_path_factory.mktemp("runtime"), prefix, **server.env())
        try:
            yield env, prefix, server
        finally:
            stop_daemon(env)
            kill_leftovers(str(prefix))




def _pids(output: str, name: str) -> list[int]:
    return [int(pid) for pid in re.findall(rf"\[INFO\] \[{re.escape(name)}\]: process started with pid \[(\d+)\]",
                                           output)]










def _stopped_within(pid: int, bound: float, what: str) -> float:
    """Seconds until ``pid`` has ended (failing the test past ``bound`` + LOAD_MARGIN)."""
    started = time.monotonic()
    wait_until(lambda: not alive(pid), bound + LOAD_MARGIN, f"the remote process to stop after {what}", period=0.05)
    elapsed = time.monotonic() - started
    print(f"remote process stopped {elapsed:.2f} s after {what} (documented bound {bound:g} s)")
    return elapsed


def test_a_remote_process_runs_beside_a_local_one_as_explained(remote, tmp_path: Path) -> None:
    env, prefix, _ = remote
    write_pair(tmp_path, prefix)
    explained = roc("-C", str(tmp_path), "launch", "pair", "--explain", "--format", "json", env=env)
    assert explained.returncode == 0, explained.stderr
    talker, listener = json.loads(explained.stdout)
    launcher = roc_launch("pair", env=env, log=tmp_path / "roc.log")
    try:
        wait_for_nodes(env, {"/local/talker", "/local/far_listener"}, timeout=60)
        launcher.wait_for_output(f"[{REMOTE}] [INFO] [", timeout=30)  # relayed, the host in the prefix
        launcher.wait_for_output("[local.far_listener]: heard: hello", timeout=30)  # it hears the local talker
        output = launcher.output()
        local_pid, = _pids(output, "local/talker")
        remote_pid, = _pids(output, REMOTE)
        assert "sshd" in map(comm, ancestors(remote_pid)) and launcher.pid not in ancestors(remote_pid)
        for entry, pid in ((talker, local_pid), (listener, remote_pid)):  # --explain said what runs
            assert proc_argv(pid) == as_proc_shows(entry["command"])
            assert os.readlink(f"/proc/{pid}/cwd") == entry["cwd"]
            environ = proc_environ(pid)
            assert {name: environ.get(name) for name in entry["env"]} == entry["env"]
        assert listener["host"] == "robot" and listener["env"]["ROC_TEST_MARK"] == "far"
        assert listener["env"]["ROS_DOMAIN_ID"] == env["ROS_DOMAIN_ID"]  # the system's ROS settings
        assert re.fullmatch(r".+@robot/local/far_listener/1", proc_environ(remote_pid)["ROC_LAUNCH_ID"])
        local_env = {k: v for k, v in proc_environ(local_pid).items() if k != "ROC_LAUNCH_ID"}
        assert local_env == {k: v for k, v in proc_environ(launcher.pid).items()}  # roc's own, nothing added
    finally:
        assert launcher.stop() == 0, launcher.output()
    assert not alive(remote_pid) and not alive(local_pid)
    output = launcher.output()
    assert f"[INFO] [{REMOTE}]: sending signal 'SIGINT' to process[{REMOTE}]" in output
    assert f"[INFO] [{REMOTE}]: process has finished cleanly [pid {remote_pid}]" in output
    log = (tmp_path / "log" / "latest_launch" / "local_far_listener.log").read_text()
    assert "[local.far_listener]: heard: hello" in log




def _ready(output: str) -> int:
    """How many times the remote listener said it was ready (relayed)."""
    return len(re.findall(rf"\[{REMOTE}\] \[INFO\] \[[\d.]+\] \[local.far_listener\]: ready", output))


def _ssh_client(launcher_pid: int) -> int:
    """roc's ssh process (the session of the remote process, the one process roc runs on its host)."""
    import psutil

    clients = [p for p in psutil.Process(launcher_pid).children() if p.name() == "ssh"]
    assert len(clients) == 1, clients
    return clients[0].pid




def test_no_remote_process_outlives_a_failure(remote, tmp_path: Path) -> None:
    """Its ssh client killed, its sshd session killed, the network cut (each time roc starts it again: it
    respawns), then roc killed: each time the process on the host stops within the documented bound."""
    env, prefix, server = remote
    write_pair(tmp_path, prefix, respawn=True)
    launcher = roc_launch("pair", env=env, log=tmp_path / "roc.log")
    failures = {  # what fails -> how, and the bound of roc/launch/remote_guard.py
        "its ssh client killed": (lambda _pid: os.kill(_ssh_client(launcher.pid), signal.SIGKILL), GRACE_SECONDS),
        "its sshd session killed": (lambda pid: os.kill(sshd_session(pid), signal.SIGKILL), GRACE_SECONDS),
        "the network cut": (lambda _pid: server.relay.cut(), SILENCE_SECONDS + GRACE_SECONDS),
        "SIGKILL of roc": (lambda _pid: launcher.stop(signal.SIGKILL), GRACE_SECONDS),
    }
    try:
        for count, (what, (fail, bound)) in enumerate(failures.items(), 1):
            wait_until(lambda n=count: _ready(launcher.output()) == n, 60, f"start {count} of the process")
            pid = _pids(launcher.output(), REMOTE)[-1]
            fail(pid)
            _stopped_within(pid, bound, what)
    finally:
        launcher.stop(signal.SIGKILL)
    output = launcher.output()
    assert output.count(f"[WARNING] [{REMOTE}]: the connection to 'robot' was lost (ssh ") == 3, output
    assert output.count(f"[ERROR] [{REMOTE}]: process has died [pid ") == 3  # lost, never stopped otherwise
    assert not any(alive(pid) for pid in _pids(output, REMOTE))
    wait_until(lambda: not kill_leftovers(str(prefix)), 2 * GRACE_SECONDS + LOAD_MARGIN, "the local guard's sweep")


def test_an_unreachable_host_fails_before_anything_starts(remote, tmp_path: Path) -> None:
    env, prefix, server = remote
    write_pair(tmp_path, prefix, host="nowhere")
    error = "host 'nowhere' cannot be reached: ssh: connect to host 127.0.0.1 port {port}: Connection refused"
    port = re.search(r"Host nowhere\n  HostName 127.0.0.1\n  Port (\d+)", server.config.read_text()).group(1)
    for extra in ((), ("--check", str(tmp_path / "roc.toml")), ("--explain",)):
        started = subprocess.run([*_roc(), "launch", "pair", *extra], cwd=tmp_path, env=env, capture_output=True,
                                 text=True, timeout=60)
        assert started.returncode == 1, started.stdout + started.stderr
        assert started.stderr == (f"roc: error: {tmp_path}/roc.toml: [launch.pair]: "
                                  f"{error.format(port=port)}\n"), extra
        assert "process started" not in started.stdout
    assert not kill_leftovers(str(prefix))


def _roc() -> list[str]:
    from helpers.build import BIN

    return [str(BIN / "roc")]


def test_a_missing_executable_or_setup_file_fails_before_anything_starts(remote, tmp_path: Path) -> None:
    env, prefix, _ = remote
    write_pair(tmp_path, prefix)
    text = (tmp_path / "roc.toml").read_text()
    (tmp_path / "roc.toml").write_text(text.replace('executable = "listener"', 'executable = "listner"'))
    started = subprocess.run([*_roc(), "launch", "pair"], cwd=tmp_path, env=env, capture_output=True, text=True,
                             timeout=60)
    assert started.returncode == 1 and started.stdout == ""
    assert started.stderr.startswith(f"roc: error: {tmp_path}/roc.toml: [launch.pair]: host 'robot': package "
                                     "'roc_launch_demo' has no executable 'listner' (its executables: args, crasher, "
                                     "listener, server, talker) ("), started.stderr
    assert started.stderr.endswith(f"{tmp_path}/roc.toml:11)\n") and started.stderr.count("\n") == 1
    (tmp_path / "roc.toml").write_text(text.replace("setup.bash", "setup.bsh"))
    started = subprocess.run([*_roc(), "launch", "pair"], cwd=tmp_path, env=env, capture_output=True, text=True,
                             timeout=60)
    assert started.returncode == 1 and started.stdout == ""
    assert started.stderr == (f"roc: error: {tmp_path}/roc.toml: [launch.pair]: host 'robot': setup file "
                              f"{prefix.parent}/setup.bsh does not exist ({tmp_path}/roc.toml:2)\n")
    assert not kill_leftovers(str(prefix))
