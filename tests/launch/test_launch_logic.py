"""Fast tests of roc launch's parts without a ROS graph: the ament index on a made-up prefix, launch
arguments, the orphan guard on real processes, the process table and its logs, roc.toml systems and their
plan."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers.launch import wait_until

from roc.errors import RocError, UsageError


@pytest.fixture
def prefix(tmp_path: Path, monkeypatch) -> Path:
    """A prefix with packages 'a' (executables, one twice) and 'b' (none), first on AMENT_PREFIX_PATH."""
    index = tmp_path / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    for name in ("a", "b", ".hidden"):
        (index / name).write_text("")
    for relative, mode in (("x", 0o755), ("plain.txt", 0o644), ("sub/x", 0o755), ("sub/y", 0o755),
                           (".cache/z", 0o755)):
        path = tmp_path / "lib" / "a" / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("#!/bin/sh\n")
        path.chmod(mode)
    monkeypatch.setenv("AMENT_PREFIX_PATH", f"{tmp_path}{os.pathsep}{sys.prefix}")
    return tmp_path


def test_the_ament_index_overlays_prefixes_and_lists_executables_as_ros2pkg(prefix: Path) -> None:
    from roc.ament_index import executables, find_executable, package_prefix, packages

    found = packages()
    assert found["a"] == found["b"] == prefix and ".hidden" not in found
    assert found["rclpy"] == Path(sys.prefix)
    assert [p.relative_to(prefix).as_posix() for p in executables("a")] == ["lib/a/x", "lib/a/sub/x", "lib/a/sub/y"]
    assert find_executable("a", "y") == prefix / "lib" / "a" / "sub" / "y"
    with pytest.raises(RocError, match=r"package 'a' has 2 executables named 'x': .*lib/a/x, .*lib/a/sub/x; remove"):
        find_executable("a", "x")
    with pytest.raises(RocError, match=r"^package 'b' has no executable 'x'; \(it installs no executables\)$"):
        find_executable("b", "x")
    with pytest.raises(RocError, match=r"package 'c' not found in the ament index \(.*\); did you mean a\?|"
                                       r"package 'c' not found"):
        package_prefix("c")


@pytest.mark.parametrize("words, parsed", [
    (["a:=1", "b:=x:=y", "a:=2"], [("a", "2"), ("b", "x:=y")]),
    (["empty:=:="], [("empty", ":=")]),
    ([], []),
])
def test_launch_arguments_follow_ros2_launchs_rules(words: list[str], parsed: list) -> None:
    from roc.launch.files import parse_arguments

    assert parse_arguments(words) == parsed


@pytest.mark.parametrize("word", ["a", ":=1", "a:=", "a=1"])
def test_a_malformed_launch_argument_is_a_usage_error(word: str) -> None:
    from roc.launch.files import parse_arguments

    with pytest.raises(UsageError, match=f"launch argument '{word}': expected NAME:=VALUE"):
        parse_arguments([word])


def test_a_missing_launch_library_is_one_line_saying_how_to_get_it(monkeypatch) -> None:
    import importlib.util

    from roc.launch.files import require_launch_library

    real = importlib.util.find_spec
    hidden = ("launch", "launch_ros")
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name in hidden else real(name, *a))
    with pytest.raises(RocError) as raised:
        require_launch_library()
    assert str(raised.value) == (f"the ROS 2 launch library (launch, launch_ros) is not installed for "
                                 f"{sys.executable}: source your ROS 2 installation (e.g. /opt/ros/jazzy/setup.bash) "
                                 "or install ros-<distro>-launch-ros, then run roc launch again")


def _alive(pid: int) -> bool:
    from roc.launch.guard import read_proc

    proc = read_proc(pid)
    return proc is not None and proc.state not in ("Z", "X")


# A parent that starts the guard and a tree of processes (a shell and its sleep, in a session of their own,
# found through the guard's token), prints their PIDs and waits to be killed.
PARENT = """
import subprocess, sys, time
from roc.launch.guard import Guard
guard = Guard()
shell = subprocess.Popen(["sh", "-c", "sleep 60 & echo $!; wait"], stdout=subprocess.PIPE, text=True,
                         start_new_session=True, env=guard.environment({"PATH": "/usr/bin:/bin"}))
sleeper = int(shell.stdout.readline())
guard.record(shell.pid)
print(shell.pid, sleeper, guard._process.pid, flush=True)
time.sleep(60)
"""


def test_the_guard_stops_a_killed_parents_process_tree() -> None:
    parent = subprocess.Popen([sys.executable, "-c", PARENT], stdout=subprocess.PIPE, text=True)
    try:
        shell, sleeper, guard = map(int, parent.stdout.readline().split())
        assert _alive(shell) and _alive(sleeper) and _alive(guard)
        parent.send_signal(signal.SIGKILL)
        parent.wait()
        wait_until(lambda: not (_alive(shell) or _alive(sleeper) or _alive(guard)), 10,
                   "the guard to stop the shell and its sleep, then exit")
    finally:
        if parent.poll() is None:
            parent.kill()
            parent.wait()


def test_closing_the_guard_stops_what_is_left_and_nothing_else() -> None:
    from roc.launch.guard import Guard

    guard = Guard()
    other = subprocess.Popen(["sleep", "60"])  # not the run's: no token, not recorded
    ours = subprocess.Popen(["sh", "-c", "trap '' TERM; sleep 60"], env=guard.environment({"PATH": "/usr/bin:/bin"}))
    try:
        wait_until(lambda: any(_alive(p) and Path(f"/proc/{p}/stat").read_text().split()[3] == str(ours.pid)
                               for p in map(int, filter(str.isdigit, os.listdir("/proc")))), 5, "the shell's sleep")
        started = time.monotonic()
        left = guard.close(grace=0.5)  # the shell ignores SIGTERM: it gets SIGKILL after the grace
        assert ours.pid in left and other.pid not in left
        assert time.monotonic() - started < 5
        assert ours.wait(timeout=5) == -signal.SIGKILL
        assert other.poll() is None
    finally:
        for process in (other, ours):
            process.kill()
            process.wait()


# Ends on its second SIGTERM only, as an rclpy node whose executor woke before rclpy's signal handler had shut
# its context down, and that no timer or message wakes again (roc.launch.guard.RESEND_SECONDS).
ENDS_ON_A_SECOND_SIGTERM = """
import signal, sys, time
received = []
signal.signal(signal.SIGTERM, lambda *_: sys.exit(0) if received else received.append(1))
print("ready", flush=True)
while True:
    time.sleep(0.05)
"""


def test_the_guard_ends_a_node_that_misses_its_first_sigterm_well_within_the_grace() -> None:
    """Issue 51: after kill -9 of roc launch, an rclpy node sometimes took the whole grace and its SIGKILL."""
    from roc.launch.guard import GRACE_SECONDS, Guard

    guard = Guard()
    node = subprocess.Popen([sys.executable, "-c", ENDS_ON_A_SECOND_SIGTERM], stdout=subprocess.PIPE, text=True,
                            env=guard.environment(dict(os.environ)))
    try:
        assert node.stdout is not None and node.stdout.readline() == "ready\n"
        started = time.monotonic()
        assert guard.close() == [node.pid]
        assert node.wait(timeout=1) == 0  # its own end, not the grace's SIGKILL
        assert time.monotonic() - started < GRACE_SECONDS / 2
    finally:
        node.kill()
        node.wait()


class Lines:
    def __init__(self) -> None:
        self.lines: list[str] = []

    def line(self, text: str) -> None:
        self.lines.append(text)


def test_the_monitor_prints_as_ros2_launch_and_keeps_each_process_row(tmp_path: Path) -> None:
    from roc.launch.monitor import Monitor

    output = Lines()
    monitor = Monitor(output, tmp_path)
    monitor.waiting("b", "node /a exists")
    monitor.started("a", 11, ["/bin/a", "--x"])
    monitor.output_text("a", "[INFO] [1795613360.189655492] [a]: one\n[WARN] [1795613360.2] [a]: two")
    assert monitor.snapshot()[1].last_line == "[INFO] [a]: one"  # the time stamp left out of the view
    monitor.output_text("a", " halves\n\n")
    monitor.exited("a", 11, 3, ["/bin/a", "--x"])
    monitor.started("a", 12, ["/bin/a", "--x"])
    monitor.stopping.set()
    monitor.exited("a", 12, -2, ["/bin/a", "--x"])
    monitor.close()
    assert output.lines == [
        "[INFO] [b]: waiting for node /a exists",
        "[INFO] [a]: process started with pid [11]",
        "[a] [INFO] [1795613360.189655492] [a]: one",
        "[a] [WARN] [1795613360.2] [a]: two halves",
        "[a] ",
        "[ERROR] [a]: process has died [pid 11, exit code 3, cmd '/bin/a --x'].",
        "[INFO] [a]: process started with pid [12]",
        "[ERROR] [a]: process has died [pid 12, exit code -2, cmd '/bin/a --x'].",
    ]
    rows = {row.name: row for row in monitor.snapshot()}
    assert (rows["a"].state, rows["a"].restarts, rows["a"].last_line) == ("stopped", 1, "[WARN] [a]: two halves")
    assert (rows["b"].state, rows["b"].detail) == ("waiting", "node /a exists")
    log = (tmp_path / "a.log").read_text().splitlines()
    assert log[0].startswith("[roc] ") and log[0].endswith("process started with pid [11]: /bin/a --x")
    assert log[1:4] == ["[INFO] [1795613360.189655492] [a]: one", "[WARN] [1795613360.2] [a]: two halves", ""]
    assert log[4].endswith("process exited with code 3") and log[-1].endswith("process exited with code -2")


SYSTEM = """
[launch.nav]
timeout = 12
[[launch.nav.process]]
package = "p"
executable = "amcl"
namespace = "robot"
after = ["service /map_server/load_map is available", "topic /scan publishes at >= 5 Hz", "process map_server"]
[[launch.nav.process]]
package = "p"
executable = "map_server"
parameters = { a = 1, b = { c = [1.5, 2.0], d = "x y" }, e = true }
remappings = { map = "/office/map" }
arguments = ["--verbose"]
[[launch.nav.process]]
package = "p"
executable = "scan"
after = ["topic /clock publishes", "node /map_server"]
"""


def test_a_system_reads_into_processes_conditions_and_ros_arguments(tmp_path: Path) -> None:
    from roc.launch.system import load_system

    (tmp_path / "roc.toml").write_text(SYSTEM)
    system = load_system(tmp_path / "roc.toml", "nav")
    amcl, map_server, scan = system.processes
    assert (system.timeout, amcl.label, map_server.label) == (12.0, "robot/amcl", "map_server")
    assert [(c.expectation.label if c.expectation else c.process) for c in amcl.after] == [
        "service /map_server/load_map is available", "topic /scan publishes at >= 5 Hz", "map_server"]
    assert amcl.after[1].expectation.values == {"min-rate": 5.0}
    assert scan.after[0].expectation.values == {"min-rate": 0.0} and scan.after[1].expectation.kind == "node"
    assert map_server.ros_arguments() == ["--ros-args", "-p", "a:=1", "-p", "b.c:=[1.5, 2.0]", "-p", 'b.d:="x y"',
                                          "-p", "e:=true", "-r", "map:=/office/map"]
    assert amcl.ros_arguments() == ["--ros-args", "-r", "__ns:=/robot"]


def test_the_plan_starts_processes_after_their_conditions(tmp_path: Path) -> None:
    from roc.launch.explain import system_entries, system_lines
    from roc.launch.plan import LazySession, plan, start_order
    from roc.launch.system import load_system

    (tmp_path / "roc.toml").write_text(SYSTEM)
    system = load_system(tmp_path / "roc.toml", "nav")
    tasks = plan(system, lambda _spec: None, LazySession(), lambda: False)
    by_key = {task.key: task for task in tasks}
    assert by_key["process:robot/amcl"].dependencies == {
        "probe:service /map_server/load_map is available", "probe:topic /scan publishes at >= 5 Hz",
        "process:map_server"}
    assert [task.key for task in start_order(tasks) if task.kind == "process"] == [
        "process:map_server", "process:robot/amcl", "process:scan"]  # by depth, then as declared
    entries = system_entries(system, tasks, lambda spec: [spec.executable, *spec.arguments], dict,
                             lambda _spec: "/")
    assert system_lines(system, entries) == [
        f"[launch.nav] of {tmp_path}/roc.toml: 3 processes; conditions wait up to 12 s",
        "map_server: starts at once", "    map_server --verbose",
        "robot/amcl: starts after: service /map_server/load_map is available, topic /scan publishes at >= 5 Hz, "
        "process map_server", "    amcl",
        "scan: starts after: topic /clock publishes, node /map_server", "    scan"]


def test_two_processes_of_one_name_are_an_error(tmp_path: Path) -> None:
    from roc.launch.system import load_system

    (tmp_path / "roc.toml").write_text('[launch.x]\n[[launch.x.process]]\npackage = "p"\nexecutable = "a"\n'
                                       '[[launch.x.process]]\npackage = "q"\nexecutable = "a"\n')
    with pytest.raises(UsageError, match=r"roc.toml:2: 'name': two processes are named 'a'; give one another name"):
        load_system(tmp_path / "roc.toml", "x")


def test_roc_toml_with_launch_systems_still_configures_the_work_verbs(tmp_path: Path) -> None:
    from roc.config import load_configuration

    (tmp_path / "roc.toml").write_text(SYSTEM + '\n[build]\nparallel-workers = 3\n')
    config = load_configuration(tmp_path, "build", None, metas=[], ignore_user_meta=True)
    assert config.effective()["parallel-workers"].value == 3


@pytest.mark.parametrize("variables", [{"ROS_LOG_DIR": "/tmp/roc-logs/../roc-logs2"}, {"ROS_LOG_DIR": "~/logs"},
                                       {"ROS_HOME": "/tmp/roc-home"}, {"ROS_LOG_DIR": "", "ROS_HOME": ""}, {}])
def test_the_ros_log_directory_is_the_launch_librarys(variables: dict[str, str], monkeypatch) -> None:
    """Where ros2 launch writes its logs (roc launch's logs outside a workspace): the launch library's own rule."""
    logging = pytest.importorskip("launch.logging")
    from roc.launch.logs import ros_log_directory

    for name in ("ROS_LOG_DIR", "ROS_HOME"):
        monkeypatch.delenv(name, raising=False)
    for name, value in variables.items():
        monkeypatch.setenv(name, value)
    assert str(ros_log_directory()) == logging._get_logging_directory()
