"""roc launch of a launch file, once it runs: Ctrl+C, SIGTERM and a closed terminal stop every process;
SIGKILL of roc leaves none behind (ros2 launch leaves them all); a failing process with and without
respawn; --check green and red; the per-process logs; the live status view on a terminal."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

import pytest
from helpers.graph import install_oracle, stop_daemon
from helpers.launch import (
    DEMO_NODES,
    demo_env,
    kill_leftovers,
    nodes,
    processes_with,
    roc_launch,
    ros2_launch,
    skip_without_launch_library,
    wait_for_nodes,
    wait_until,
)

PACKAGE = "roc_launch_demo"


@pytest.fixture(scope="module")
def demo(tmp_path_factory, launch_demo_prefix):
    skip_without_launch_library()
    prefix = launch_demo_prefix
    env = demo_env(30, tmp_path_factory.mktemp("runtime"), prefix)
    yield env, prefix
    stop_daemon(env)
    kill_leftovers(str(prefix))


def _no_process_left(prefix: Path, timeout: float = 0.0) -> None:
    if timeout:
        wait_until(lambda: not processes_with(str(prefix)), timeout, "every launched process to end")
    assert processes_with(str(prefix)) == []


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP], ids=["ctrl-c", "sigterm", "hangup"])
def test_a_signal_stops_every_process_and_exits_0(demo, tmp_path: Path, signum: int) -> None:
    env, prefix = demo
    launcher = roc_launch(PACKAGE, "demo.launch.py", env=env, log=tmp_path / "roc.log")
    try:
        wait_for_nodes(env, DEMO_NODES)
        wait_until(lambda: launcher.output().count("]: ready") == 3, 30, "the nodes to be ready")
        assert len(processes_with(str(prefix))) == 5  # the launch runner, the fork server and three nodes
    finally:
        code = launcher.stop(signum)
    assert code == 0, launcher.output()
    _no_process_left(prefix)  # already when roc has exited
    output = launcher.output()
    assert "user interrupted with ctrl-c (SIGINT)" in output  # roc passed one SIGINT to the launch library
    assert output.count("process has finished cleanly") == 3, output
    wait_until(lambda: not nodes(env) & DEMO_NODES, 20, "the nodes to leave the graph")


@pytest.mark.slow
def test_sigkill_of_roc_leaves_no_process_behind_unlike_ros2_launch(demo, tmp_path: Path) -> None:
    env, prefix = demo
    reason = install_oracle(launch=True)
    if not reason:  # the oracle's behaviour, which roc's differs from: its nodes outlive it
        oracle = ros2_launch(PACKAGE, "demo.launch.py", env=env, log=tmp_path / "ros2.log")
        try:
            wait_for_nodes(env, DEMO_NODES)
        finally:
            oracle.stop(signal.SIGKILL)
        time.sleep(2)  # nothing is expected to happen: the orphans keep running
        assert len(kill_leftovers(str(prefix))) == 3
    launcher = roc_launch(PACKAGE, "demo.launch.py", env=env, log=tmp_path / "roc.log")
    try:
        wait_for_nodes(env, DEMO_NODES)
    finally:
        assert launcher.stop(signal.SIGKILL) == -signal.SIGKILL
    _no_process_left(prefix, timeout=20)  # the guard saw roc go and stopped them


@pytest.mark.slow
@pytest.mark.parametrize("respawn", [False, True], ids=["once", "respawned"])
def test_a_failing_process_is_reported_and_restarted_only_with_respawn(demo, tmp_path: Path, respawn: bool) -> None:
    env, prefix = demo
    launcher = roc_launch(PACKAGE, "crash.launch.py", f"respawn:={str(respawn).lower()}", env=env,
                          log=tmp_path / "roc.log")
    try:
        launcher.wait_for_output("[ERROR] [crasher-2]: process has died [pid ")
        if respawn:
            wait_until(lambda: launcher.output().count("[INFO] [crasher-2]: process started") >= 3, 30,
                       "two restarts")
        else:
            time.sleep(1.5)  # the time a respawn would take (0.5 s delay and start): there must be none
        # the other process (talker-1, node /steady) runs on: the launch goes on after the crash (on a busy
        # machine the node may need a few seconds more to start and be seen)
        wait_until(lambda: "/steady" in nodes(env), 30, "/steady in the graph")
        assert launcher.process.poll() is None
    finally:
        assert launcher.stop() == 0
    _no_process_left(prefix)
    output = launcher.output()
    starts = output.count("[INFO] [crasher-2]: process started")
    assert starts >= 3 if respawn else starts == 1, output
    assert "exit code 3, cmd '" in output
    assert '[args-3] ["printed", ' not in output  # its output is 'log': stdout in its log file only
    assert '["printed", "--ros-args"' in (tmp_path / "log" / "latest_launch" / "args-3.log").read_text()
    log = (tmp_path / "log" / "latest_launch" / "crasher-2.log").read_text()
    assert log.count("[roc] ") >= 2 * min(starts, 3)  # each start and each exit
    assert "[ERROR] [" in log and "failing with exit code 3" in log
    assert (tmp_path / "log" / "latest_launch" / "launch" / "launch.log").is_file()  # the library's own log


@pytest.mark.slow
def test_launch_prefix_its_filter_and_all_output_as_in_ros2_launch(demo, tmp_path: Path) -> None:
    import re

    env, prefix = demo
    launcher = roc_launch("-a", "--launch-prefix", "env ROC_PREFIXED=yes", "--launch-prefix-filter", "talker",
                          PACKAGE, "crash.launch.py", env=env, log=tmp_path / "roc.log")
    try:
        output = launcher.wait_for_output('[args-3] ["printed", ')  # shown although its output is 'log'
        talker = int(re.search(r"\[INFO\] \[env-1\]: process started with pid \[(\d+)\]", output)[1])  # named after env
        assert b"ROC_PREFIXED=yes" in Path(f"/proc/{talker}/environ").read_bytes().split(b"\0")
        died = launcher.wait_for_output("[ERROR] [crasher-2]: process has died")
        assert re.search(r"process has died \[pid \d+, exit code 3, cmd '/\S+/crasher ", died)  # no prefix
    finally:
        assert launcher.stop() == 0
    _no_process_left(prefix)


CHECK_GREEN = """
[check]
timeout = 20
nodes = ["/robot1/talker", "/robot1/listener", "/map_server"]
[[check.topic]]
name = "/robot1/news"
min-rate = 3
publishers = 1
subscribers = 1
[[check.service]]
name = "/map_server/load_map"
"""


@pytest.mark.slow
@pytest.mark.parametrize("green", [True, False], ids=["green", "red"])
def test_check_then_exit_is_a_launch_smoke_test(demo, tmp_path: Path, green: bool) -> None:
    env, prefix = demo
    check = tmp_path / "expected.toml"
    check.write_text(CHECK_GREEN if green else '[check]\ntimeout = 3\nnodes = ["/robot1/talker", "/ghost"]\n')
    launcher = roc_launch(PACKAGE, "demo.launch.py", "--check", str(check), "--exit-after-check", env=env,
                          log=tmp_path / "roc.log")
    code = launcher.process.wait(timeout=90)
    output = launcher.output()
    _no_process_left(prefix)
    if green:
        assert code == 0, output
        assert "Summary: 5 probes finished" in output
        assert "--exit-after-check: every expectation holds, stopping" in output
    else:
        assert code == 1, output
        assert "Failed   <<< node /ghost" in output and "1 probe failed" in output
        assert "Finished <<< node /robot1/talker" in output


@pytest.mark.slow  # over a second (the quick loop stays under 45 s)
def test_a_bad_check_file_stops_before_anything_starts(demo, tmp_path: Path) -> None:
    env, prefix = demo
    check = tmp_path / "expected.toml"
    check.write_text("[check]\nnodez = []\n")
    launcher = roc_launch(PACKAGE, "demo.launch.py", "--check", str(check), env=env, log=tmp_path / "roc.log")
    assert launcher.process.wait(timeout=30) == 2
    assert launcher.output() == f"roc: error: {check}:2: 'nodez': unknown key of [check]; did you mean 'nodes'? " \
                                "use timeout, rate-window, nodes or [[check.topic]], [[check.service]], " \
                                "[[check.action]], [[check.parameter]] (see 'roc launch --help')\n"
    assert processes_with(str(prefix)) == []


@pytest.mark.slow
def test_the_live_view_on_a_terminal_shows_each_process(demo, tmp_path: Path) -> None:
    import pty
    import re
    import select

    env, prefix = demo
    pid, terminal = pty.fork()
    if pid == 0:  # the child: roc launch on a terminal of 140 columns
        os.chdir(tmp_path)
        os.execve(str(Path(env["PATH"].split(os.pathsep)[0]) / "roc"),
                  ["roc", "launch", "--log-base", str(tmp_path / "log"), PACKAGE, "crash.launch.py", "respawn:=true"],
                  {**env, "TERM": "xterm", "COLUMNS": "140", "LINES": "40"})
    screen = b""

    def read(seconds: float) -> str:
        nonlocal screen
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            if select.select([terminal], [], [], 0.1)[0]:
                try:
                    data = os.read(terminal, 65536)
                except OSError:
                    break
                if not data:
                    break
                screen += data
        return re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", screen.decode(errors="replace"))

    try:
        text = wait_until(lambda: (t := read(0.5)) and re.search(r"crasher-2 +\d+ +running +[1-9]", t) and t, 40,
                          "a row of the restarted crasher in the live view")
        assert re.search(r"process +pid +state +restarts +cpu +memory +uptime +last line", text)
        steady = r"talker-1 +\d+ +running +0 +\d+% +\d+ MiB +\d+s +\[INFO\] \[steady\]: ready"
        assert re.search(steady, text), text[-3000:]
        assert "[INFO] [talker-1]: process started with pid" in text  # the lines scroll above it
    finally:
        os.kill(pid, signal.SIGINT)
        read(10)
        _, status = os.waitpid(pid, 0)
        os.close(terminal)
    assert os.waitstatus_to_exitcode(status) == 0
    _no_process_left(prefix)


STUBBORN = """
from launch import LaunchDescription
from launch.actions import ExecuteProcess


def generate_launch_description():
    return LaunchDescription([ExecuteProcess(cmd=['sh', '{script}'], output='screen')])
"""


@pytest.mark.slow  # over a second (the quick loop stays under 45 s)
def test_a_second_ctrl_c_kills_every_process_at_once(demo, tmp_path: Path) -> None:
    env, _ = demo
    script = tmp_path / "stubborn.sh"  # ignores SIGINT: the library would wait 5 s before its SIGTERM
    script.write_text("trap '' INT\necho ready\nwhile true; do sleep 1; done\n")
    (tmp_path / "stubborn.launch.py").write_text(STUBBORN.format(script=script))
    launcher = roc_launch(str(tmp_path / "stubborn.launch.py"), env=env, log=tmp_path / "roc.log")
    try:
        launcher.wait_for_output("[sh-1] ready")
        launcher.process.send_signal(signal.SIGINT)
        launcher.wait_for_output("[INFO] [sh-1]: sending signal 'SIGINT' to process[sh-1]")
        started = time.monotonic()
    finally:
        code = launcher.stop(signal.SIGINT, timeout=10)
    assert code == 130 and time.monotonic() - started < 4
    assert "[WARNING] [roc]: SIGINT again, killing every process now" in launcher.output()
    assert processes_with(str(tmp_path)) == []
