"""roc's remote guard (roc/launch/remote_guard.py) without SSH: the command roc has the remote login shell
run, run here by sh with roc's payload on its standard input, as sshd would. It sources the setup files,
finds the executable as ros2 run does, reports, passes signals on, and stops the process when its session
ends; roc.toml's hosts and host keys read with their errors."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import time
from pathlib import Path

import pytest
from helpers.ssh import alive

from roc.errors import UsageError
from roc.launch.remote import REMOTE_COMMAND, payload
from roc.launch.remote_guard import GRACE_SECONDS, MARK


def _prefix(tmp_path: Path) -> Path:
    """An install prefix with package 'demo' and its executable 'sleeper' (a shell script that sleeps),
    and a setup file that puts the prefix on AMENT_PREFIX_PATH."""
    prefix = tmp_path / "install"
    (prefix / "share" / "ament_index" / "resource_index" / "packages").mkdir(parents=True)
    (prefix / "share" / "ament_index" / "resource_index" / "packages" / "demo").write_text("")
    (prefix / "lib" / "demo").mkdir(parents=True)
    sleeper = prefix / "lib" / "demo" / "sleeper"
    sleeper.write_text('#!/bin/sh\necho "sleeping with $DEMO_WORD" "$@"\nexec sleep 60\n')
    sleeper.chmod(0o755)
    (tmp_path / "setup.sh").write_text(f'export AMENT_PREFIX_PATH="{prefix}"\n')
    return prefix


def _guard(spec: dict) -> subprocess.Popen:
    process = subprocess.Popen(["sh", "-c", REMOTE_COMMAND], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE)
    assert process.stdin is not None
    process.stdin.write(payload(spec))
    process.stdin.flush()
    return process


def _events(stream) -> list[dict]:
    return [json.loads(line[len(MARK):]) for line in stream.read().decode().splitlines() if line.startswith(MARK)]


def _next_event(process: subprocess.Popen) -> dict:
    assert process.stderr is not None
    line = process.stderr.readline().decode()
    assert line.startswith(MARK), line
    return json.loads(line[len(MARK):])


def _run_spec(tmp_path: Path, **changes) -> dict:
    return {"mode": "run", "setup": [str(tmp_path / "setup.sh")], "package": "demo", "executable": "sleeper",
            "arguments": ["--ros-args", "-r", "__node:=x"], "env": {"DEMO_WORD": "hello"},
            "token": f"test-{os.getpid()}-{time.monotonic_ns()}", **changes}




def test_the_guard_stops_its_process_when_the_session_ends(tmp_path: Path) -> None:
    prefix = _prefix(tmp_path)
    guard = _guard(_run_spec(tmp_path))
    try:
        started = _next_event(guard)
        assert started["event"] == "started"
        assert started["cmd"] == [str(prefix / "lib" / "demo" / "sleeper"), "--ros-args", "-r", "__node:=x"]
        assert guard.stdout is not None
        assert guard.stdout.readline() == b"sleeping with hello --ros-args -r __node:=x\n"  # straight into the session
        pid = started["pid"]
        assert alive(pid)
        assert guard.stdin is not None
        guard.stdin.close()  # the session ends: roc, its ssh or the connection is gone
        assert guard.wait(timeout=GRACE_SECONDS + 10) == 128 + signal.SIGTERM
    finally:
        guard.kill()
    assert not alive(pid)
    exited = [event for event in _events(guard.stderr) if event["event"] == "exited"]
    assert exited == [{"event": "exited", "code": -signal.SIGTERM, "reason": "the SSH session closed"}]


def test_the_guard_passes_signals_to_its_process_and_reports_its_exit(tmp_path: Path) -> None:
    _prefix(tmp_path)
    guard = _guard(_run_spec(tmp_path))
    try:
        pid = _next_event(guard)["pid"]
        assert guard.stdin is not None
        guard.stdin.write(b"\n\nsignal 2\n")  # heartbeats, then roc's stop rule's first signal
        guard.stdin.flush()
        assert guard.wait(timeout=20) == 128 + signal.SIGINT
    finally:
        guard.kill()
    assert not alive(pid)
    assert [e for e in _events(guard.stderr) if e["event"] == "exited"] == [
        {"event": "exited", "code": -signal.SIGINT, "reason": ""}]


@pytest.mark.slow  # six Pythons started
@pytest.mark.parametrize("change, error", [
    ({"executable": "sleepr"}, "package 'demo' has no executable 'sleepr' (its executables: sleeper)"),
    ({"package": "nope"}, "package 'nope' is not installed ({prefix})"),
    ({"setup": ["/nonexistent/setup.bash"]}, "setup file /nonexistent/setup.bash does not exist"),
])
def test_the_guard_says_what_is_missing_and_starts_nothing(tmp_path: Path, change: dict, error: str) -> None:
    prefix = _prefix(tmp_path)
    run = _guard(_run_spec(tmp_path, **change))
    check = _guard({"mode": "check", "setup": change.get("setup", [str(tmp_path / "setup.sh")]),
                    "executables": [[change.get("package", "demo"), change.get("executable", "sleeper")],
                                    ["demo", "sleeper"]]})
    assert run.wait(timeout=20) == 2 and check.wait(timeout=20) == 0
    assert _events(run.stderr) == [{"event": "error", "message": error.format(prefix=prefix)}]
    checked, = _events(check.stderr)
    if "setup" in change:
        assert checked["error"] == error and checked["found"] == {}
    else:
        assert checked["missing"] == [error.format(prefix=prefix)]
        assert checked["found"] == {"demo/sleeper": str(prefix / "lib" / "demo" / "sleeper")}


HOSTS = """
[launch.s.hosts."user@robot"]
setup = ["/opt/ros/jazzy/setup.bash", "~/ws/install/setup.bash"]
[launch.s.hosts.board]
setup = "/opt/ros/jazzy/setup.sh"
[[launch.s.process]]
package = "p"
executable = "a"
host = "user@robot"
[[launch.s.process]]
package = "p"
executable = "b"
host = "laptop"
[[launch.s.process]]
package = "p"
executable = "c"
"""


def test_a_system_reads_its_hosts(tmp_path: Path) -> None:
    from roc.launch.system import load_system

    (tmp_path / "roc.toml").write_text(HOSTS)
    system = load_system(tmp_path / "roc.toml", "s")
    assert [(p.label, p.host) for p in system.processes] == [("a", "user@robot"), ("b", "laptop"), ("c", "")]
    assert {name: host.setup for name, host in system.hosts.items()} == {
        "user@robot": ["/opt/ros/jazzy/setup.bash", "~/ws/install/setup.bash"],
        "board": ["/opt/ros/jazzy/setup.sh"], "laptop": []}
    assert system.hosts["user@robot"].where == f"{tmp_path}/roc.toml:2"
    assert [p.label for p in system.remote()] == ["a", "b"]


@pytest.mark.parametrize("text, error", [
    ('[launch.x]\nhosts = 3\n', "roc.toml:2: 'hosts': expected tables [launch.NAME.hosts.\"DEST\"], got 3"),
    ('[launch.x.hosts.r]\nsetup = 5\n', "roc.toml:2: 'setup': expected a string or a list, got 5"),
    ('[launch.x.hosts.r]\nsteup = "a"\n', "roc.toml:2: 'steup': unknown key of [launch.x.hosts.\"r\"]; "),
    ('[launch.x.hosts.r]\nsetup = ["a", 1]\n', "roc.toml:2: 'setup': expected a file or a list of files to source"),
    ('[[launch.x.process]]\npackage = "p"\nexecutable = "a"\nhost = "-oProxyCommand=x"\n',
     "roc.toml:4: 'host': '-oProxyCommand=x' is not an SSH destination"),
])
def test_a_bad_host_is_one_line_naming_file_line_and_key(tmp_path: Path, text: str, error: str) -> None:
    from roc.launch.system import load_system

    (tmp_path / "roc.toml").write_text(text + ('' if "process" in text else '[[launch.x.process]]\npackage = "p"\n'
                                               'executable = "a"\n'))
    with pytest.raises(UsageError) as raised:
        load_system(tmp_path / "roc.toml", "x")
    assert str(raised.value).startswith(f"{tmp_path}/{error}"), str(raised.value)


def test_a_remote_process_shows_its_host_and_the_usage_its_host_reports(tmp_path: Path) -> None:
    """Its lines and its row of the live view say ``HOST:NAME``; its CPU and memory are what its host
    reported, never those of a local process that happens to have its PID (here: this test's own)."""
    import io

    from rich.console import Console

    from roc.launch.monitor import Monitor
    from roc.launch.view import LiveView, PlainOutput

    lines = io.StringIO()
    monitor = Monitor(PlainOutput(lines), None)
    monitor.place("lidar", "user@robot")
    monitor.waiting("lidar", "process driver started")
    monitor.started("lidar", os.getpid(), ["/opt/ros/jazzy/lib/drivers/lidar"])
    monitor.output_text("lidar", "[INFO] [1795613360.1] [lidar]: spinning\n")
    monitor.usage("lidar", 12.4, 48 * 1024 * 1024)
    assert lines.getvalue().splitlines() == [
        "[INFO] [user@robot:lidar]: waiting for process driver started",
        f"[INFO] [user@robot:lidar]: process started with pid [{os.getpid()}]",
        "[user@robot:lidar] [INFO] [1795613360.1] [lidar]: spinning"]
    view = LiveView.__new__(LiveView)  # the table alone, without starting the live display
    view.rows, view.title, view.usage = monitor.snapshot, "roc launch demo", lambda pid: ("99%", "1 GiB")
    console = Console(file=io.StringIO(), width=120, color_system=None)
    console.print(view)
    row = next(line for line in console.file.getvalue().splitlines() if "lidar" in line)
    assert row.split()[:7] == ["user@robot:lidar", str(os.getpid()), "running", "0", "12%", "48", "MiB"]
