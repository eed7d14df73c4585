"""roc launch NAME: systems declared in roc.toml, started by roc's engine: a later process waits for a
service; --explain; a condition never met; respawn; SIGKILL of roc; --check; errors naming file, line
and key."""

from __future__ import annotations

import json
import re
import signal
import time
from pathlib import Path

import pytest
from helpers.graph import graph_env, roc, stop_daemon
from helpers.launch import (
    demo_env,
    kill_leftovers,
    nodes,
    process_view,
    processes_with,
    roc_launch,
    wait_for_nodes,
    wait_until,
)

SYSTEM = """
[launch.demo]
timeout = 30

[[launch.demo.process]]
package = "roc_launch_demo"
executable = "server"
name = "map_server"
parameters = { delay = 2.0, map = { file = "office.yaml", resolution = 0.05 } }

[[launch.demo.process]]
package = "roc_launch_demo"
executable = "talker"
namespace = "robot1"
parameters = { rate = 5.0, greeting = "hi" }
remappings = { chatter = "news" }
after = ["service /map_server/load_map is available"]

[[launch.demo.process]]
package = "roc_launch_demo"
executable = "listener"
namespace = "robot1"
remappings = { chatter = "news" }
after = ["process robot1/talker started"]
"""

FAILING = """
[launch.failing]
[[launch.failing.process]]
package = "roc_launch_demo"
executable = "crasher"
respawn = {respawn}
respawn-delay = 0.3
parameters = {{ after = 0.3 }}
"""

NEVER = """
[launch.never]
timeout = 3
[[launch.never.process]]
package = "roc_launch_demo"
executable = "talker"
after = ["node /nobody exists"]
"""


@pytest.fixture(scope="module")
def demo(tmp_path_factory, launch_demo_prefix):
    prefix = launch_demo_prefix
    env = demo_env(31, tmp_path_factory.mktemp("runtime"), prefix)
    yield env, prefix
    stop_daemon(env)
    kill_leftovers(str(prefix))


def _index(output: str, text: str) -> int:
    assert text in output, output
    return output.index(text)


@pytest.mark.slow
def test_a_later_process_waits_for_a_service(demo, tmp_path: Path) -> None:
    env, prefix = demo
    (tmp_path / "roc.toml").write_text(SYSTEM)
    launcher = roc_launch("demo", env=env, log=tmp_path / "roc.log")
    try:
        wait_for_nodes(env, {"/map_server", "/robot1/talker", "/robot1/listener"}, timeout=60)
        launcher.wait_for_output("[robot1/listener] [INFO] [")
        params = json.loads(roc("param", "dump", "/map_server", "--format", "json", env=env).stdout)
        assert params["/map_server"]["ros__parameters"]["map"] == {"file": "office.yaml", "resolution": 0.05}
        server, = _fork_servers(prefix)  # the nodes were forked from roc's warm interpreter
        assert _started(launcher.output()) == {"map_server": ("server", server), "robot1/talker": ("talker", server),
                                               "robot1/listener": ("listener", server)}
    finally:
        assert launcher.stop() == 0
    assert processes_with(str(prefix)) == []
    output = launcher.output()
    assert "[map_server] [INFO] [" in output  # its 'ready', logged once the service exists
    met = _index(output, "[INFO] [roc]: service /map_server/load_map is available: met after ")
    talker = _index(output, "[INFO] [robot1/talker]: process started with pid [")
    listener = _index(output, "[INFO] [robot1/listener]: process started with pid [")
    assert _index(output, "[INFO] [map_server]: process started") < met < talker < listener
    waited = float(re.search(r"load_map is available: met after ([\d.]+) s", output)[1])
    assert waited >= 2.0  # the server creates its service 2 s after it starts (its 'delay')
    assert "[INFO] [robot1/talker]: waiting for service /map_server/load_map is available" in output
    assert output.count("process has finished cleanly") == 3, output
    log = (tmp_path / "log" / "latest_launch" / "robot1_talker.log").read_text()
    assert "[INFO] [" in log and "[robot1.talker]: ready" in log


def _started(output: str) -> dict[str, tuple[str, int]]:
    """Each process roc said it started: its name as ps shows it, and its parent's PID."""
    started = re.findall(r"\[INFO\] \[([\w/-]+)\]: process started with pid \[(\d+)\]", output)
    return {label: (process_view(int(pid))["comm"], process_view(int(pid))["ppid"]) for label, pid in started}


def _fork_servers(prefix: Path) -> list[int]:
    return [pid for pid in processes_with(str(prefix)) if process_view(pid)["comm"] == "roc-forkserver"]


@pytest.mark.slow
@pytest.mark.parametrize("how", ["--no-warm-start", "warm-start = false"])
def test_warm_start_can_be_turned_off(demo, tmp_path: Path, how: str) -> None:
    env, prefix = demo
    system = SYSTEM.replace("delay = 2.0", "delay = 0.0")
    if how.startswith("warm-start"):  # for the talker alone
        system = system.replace('executable = "talker"', f'executable = "talker"\n{how}')
    (tmp_path / "roc.toml").write_text(system)
    args = ("demo", how) if how.startswith("--") else ("demo",)
    launcher = roc_launch(*args, env=env, log=tmp_path / "roc.log")
    try:
        wait_for_nodes(env, {"/map_server", "/robot1/talker", "/robot1/listener"}, timeout=60)
        launcher.wait_for_output("[robot1/listener] [INFO] [")  # the talker's messages arrive
        started, servers = _started(launcher.output()), _fork_servers(prefix)
    finally:
        assert launcher.stop() == 0
    assert processes_with(str(prefix)) == []
    logs = tmp_path / "log" / "latest_launch"
    warm = {name for name in ("map_server", "robot1_talker", "robot1_listener")
            if "(warm start)" in (logs / f"{name}.log").read_text()}
    if how.startswith("--"):  # every node is a child of roc itself
        assert servers == [] and warm == set()
        assert started == {"map_server": ("server", launcher.pid), "robot1/talker": ("talker", launcher.pid),
                           "robot1/listener": ("listener", launcher.pid)}
    else:
        assert len(servers) == 1 and warm == {"map_server", "robot1_listener"}
        assert started == {"map_server": ("server", servers[0]), "robot1/talker": ("talker", launcher.pid),
                           "robot1/listener": ("listener", servers[0])}


@pytest.mark.slow  # it needs the demo package built (the quick loop stays under 45 s)
def test_explain_says_what_each_process_waits_for(demo, tmp_path: Path) -> None:
    env, prefix = demo
    (tmp_path / "roc.toml").write_text(SYSTEM)
    explained = roc("-C", str(tmp_path), "launch", "demo", "--explain", env=env)
    assert explained.returncode == 0, explained.stderr
    lib = prefix / "lib" / "roc_launch_demo"
    assert explained.stdout == (
        f"[launch.demo] of {tmp_path}/roc.toml: 3 processes; conditions wait up to 30 s\n"
        "map_server: starts at once\n"
        f"    {lib}/server --ros-args -r __node:=map_server -p delay:=2.0 -p 'map.file:=\"office.yaml\"' "
        "-p map.resolution:=0.05\n"
        "robot1/talker: starts after: service /map_server/load_map is available\n"
        f"    {lib}/talker --ros-args -r __ns:=/robot1 -p rate:=5.0 -p 'greeting:=\"hi\"' -r chatter:=news\n"
        "robot1/listener: starts after: process robot1/talker started\n"
        f"    {lib}/listener --ros-args -r __ns:=/robot1 -r chatter:=news\n")
    assert processes_with(str(prefix)) == []


@pytest.mark.slow
def test_a_condition_never_met_starts_nothing_after_it_and_fails(demo, tmp_path: Path) -> None:
    env, prefix = demo
    (tmp_path / "roc.toml").write_text(NEVER)
    launcher = roc_launch("never", env=env, log=tmp_path / "roc.log")
    assert launcher.process.wait(timeout=60) == 1
    output = launcher.output()
    assert "[ERROR] [roc]: node /nobody exists: not met within 3 s: fail: no node /nobody (nodes: " in output
    assert "[ERROR] [talker]: not started: it waits for 'node /nobody exists', which was not met" in output
    assert "process started" not in output


@pytest.mark.slow
@pytest.mark.parametrize("respawn", [False, True], ids=["once", "respawned"])
def test_a_failing_process_fails_the_run_unless_respawned(demo, tmp_path: Path, respawn: bool) -> None:
    env, prefix = demo
    (tmp_path / "roc.toml").write_text(FAILING.format(respawn=str(respawn).lower()))
    launcher = roc_launch("failing", env=env, log=tmp_path / "roc.log")
    if respawn:
        wait_until(lambda: launcher.output().count("[INFO] [crasher]: process started") >= 3, 40, "two restarts")
        assert launcher.stop() == 0
    else:
        assert launcher.process.wait(timeout=40) == 1  # its only process failed
    output = launcher.output()
    assert "[ERROR] [crasher]: process has died [pid " in output and ", exit code 3, cmd '" in output
    assert (output.count("[INFO] [crasher]: process started") >= 3) == respawn
    # a process alone with its interpreter starts as usual; one that respawns is forked from a fork server
    log = (tmp_path / "log" / "latest_launch" / "crasher.log").read_text()
    assert (log.count("(warm start): ") >= 3) == respawn
    assert processes_with(str(prefix)) == []


@pytest.mark.slow
def test_sigkill_of_roc_leaves_no_process_of_the_system(demo, tmp_path: Path) -> None:
    env, prefix = demo
    (tmp_path / "roc.toml").write_text(SYSTEM.replace("delay = 2.0", "delay = 0.0"))
    launcher = roc_launch("demo", env=env, log=tmp_path / "roc.log")
    try:
        wait_for_nodes(env, {"/map_server", "/robot1/talker", "/robot1/listener"}, timeout=60)
    finally:
        assert launcher.stop(signal.SIGKILL) == -signal.SIGKILL
    wait_until(lambda: not processes_with(str(prefix)), 20, "the guard to stop every process")
    wait_until(lambda: not nodes(env) & {"/map_server", "/robot1/talker"}, 20, "the nodes to leave the graph")


@pytest.mark.slow
def test_check_after_start_up_with_exit(demo, tmp_path: Path) -> None:
    env, prefix = demo
    (tmp_path / "roc.toml").write_text(SYSTEM.replace("delay = 2.0", "delay = 0.5") + """
[check]
timeout = 20
nodes = ["/map_server", "/robot1/talker", "/robot1/listener"]
[[check.topic]]
name = "/robot1/news"
min-rate = 3
""")
    started = time.monotonic()
    launcher = roc_launch("demo", "--check", str(tmp_path / "roc.toml"), "--exit-after-check", env=env,
                          log=tmp_path / "roc.log")
    assert launcher.process.wait(timeout=90) == 0, launcher.output()
    assert "Summary: 4 probes finished" in launcher.output()
    assert time.monotonic() - started < 60
    assert processes_with(str(prefix)) == []


@pytest.mark.parametrize("text, error", [
    ('[launch.x]\n[[launch.x.process]]\npakage = "a"\n',
     "roc.toml:3: 'pakage': unknown key of [[launch.x.process]]; did you mean 'package'? use package, "),
    ('[launch.x]\n[[launch.x.process]]\npackage = "a"\nexecutable = "b"\n'
     '[[launch.x.process]]\npackage = "a"\nexecutable = "c"\nafter = ["service /x is up"]\n',
     "roc.toml:8: 'after': cannot read the condition 'service /x is up'; write one of 'node NAME exists', "),
    ('[launch.x]\n[[launch.x.process]]\npackage = "a"\nexecutable = "b"\nafter = ["process c started"]\n',
     "roc.toml:2: 'after': 'process c started': no process of the system is named 'c'; (processes: b)"),
    ('[launch.x]\ntimeout = "long"\n', "roc.toml:2: 'timeout': expected a number, got 'long'"),
    ('[launch.x]\n[[launch.x.process]]\npackage = "a"\n', "roc.toml:2: 'executable': missing in [[launch.x.process]]"),
    ('[launch.x]\n[[launch.x.process]]\npackage = "a"\nexecutable = "b"\nrespawn = "yes"\n',
     "roc.toml:5: 'respawn': expected true or false, got 'yes'"),
    ('[launch.x]\n[[launch.x.process]]\npackage = "a"\nexecutable = "b"\nafter = ["process c started"]\n'
     '[[launch.x.process]]\npackage = "a"\nexecutable = "c"\nafter = ["process b"]\n',
     "roc.toml: the processes of [launch.x] wait for each other in a circle"),
])
def test_a_bad_system_is_one_line_naming_file_line_and_key(tmp_path: Path, text: str, error: str) -> None:
    """Told before anything is looked up: no package needs to be installed."""
    env = graph_env(31, tmp_path / "runtime")
    (tmp_path / "roc.toml").write_text(text)
    result = roc("-C", str(tmp_path), "launch", "x", "--explain", env=env)
    assert result.returncode == 2
    assert result.stderr.startswith(f"roc: error: {tmp_path}/{error}"), result.stderr
    assert result.stderr.count("\n") == 1
