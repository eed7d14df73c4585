"""Warm start (roc/launch/warm_start.py, forkserver.py, warm_loop.py): a script forked from the fork server
looks and behaves as the same script run by exec (the oracle, side by side): its arguments, names, paths,
streams, process group, process name and command line, exit code, traceback and signals. Which scripts a
server takes; what happens when the server dies or is not used; the launch runner's event loop forking."""

from __future__ import annotations

import asyncio
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.launch import process_view, wait_until

from roc.launch import warm_loop
from roc.launch.warm_start import ForkedProcess, ForkServer, WarmStart, _server_key, script_interpreter, start_server

REPORT = """
import json, os, sys
print(json.dumps({
    "argv": sys.argv, "orig_argv": sys.orig_argv, "name": __name__, "file": __file__, "path0": sys.path[0],
    "executable": sys.executable, "cwd": os.getcwd(), "own_group": os.getpgid(0) == os.getpid(),
    "stdin": sys.stdin.read(), "comm": open("/proc/self/comm").read(),
    "line_buffering": [sys.stdout.line_buffering, sys.stderr.line_buffering],
    "main_module": sys.modules["__main__"].__file__,
}))
sys.stderr.write("to stderr\\n")
sys.exit(7)
"""

FAILING = """
def deeper():
    raise ValueError("broken on purpose")

deeper()
"""

SLEEPER = """
import sys, time
print("ready", flush=True)
time.sleep(60)
"""


def _script(directory: Path, name: str, body: str, shebang: str = f"#!{sys.executable}") -> Path:
    path = directory / name
    path.write_text(f"{shebang}\n{body}")
    path.chmod(0o755)
    return path


@pytest.fixture(scope="module")
def env(tmp_path_factory) -> dict[str, str]:
    bin_dir = tmp_path_factory.mktemp("bin")
    os.symlink(sys.executable, bin_dir / "python3")  # what '#!/usr/bin/env python3' finds
    return {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ.get('PATH', os.defpath)}"}


@pytest.fixture(scope="module")
def server(env):
    process, client = _own_server(env)
    yield client
    client.close()
    process.wait(timeout=10)


def _own_server(env: dict[str, str]) -> tuple[subprocess.Popen, ForkServer]:
    process, channel = start_server(sys.executable, env)
    return process, ForkServer(channel, sys.executable, env)


def _ready(process: subprocess.Popen | ForkedProcess) -> None:
    assert process.stdout is not None and process.stdout.readline() == b"ready\n"


def _fork_sleeper(server: ForkServer, args: list[str], cwd: Path, pgid: int = 0) -> ForkedProcess:
    """``args`` (SLEEPER's script) forked, once it has said it is ready."""
    forked = server.popen(args, subprocess.DEVNULL, subprocess.PIPE, None, str(cwd), pgid=pgid)
    _ready(forked)
    return forked


def _exec(args: list[str], env: dict[str, str], cwd: Path, stdin: bytes = b"") -> tuple[int, bytes, bytes]:
    done = subprocess.run(args, env=env, cwd=cwd, input=stdin, capture_output=True, process_group=0, timeout=30)
    return done.returncode, done.stdout, done.stderr


def _fork(server: ForkServer, args: list[str], cwd: Path, stdin: bytes = b"") -> tuple[int, bytes, bytes]:
    process = server.popen(args, subprocess.PIPE, subprocess.PIPE, subprocess.PIPE, str(cwd))
    assert process.stdin and process.stdout and process.stderr
    process.stdin.write(stdin)
    process.stdin.close()
    out, err = process.stdout.read(), process.stderr.read()
    return process.wait(timeout=30), out, err


@pytest.mark.parametrize("shebang", [f"#!{sys.executable}", "#!/usr/bin/env python3"], ids=["absolute", "env"])
def test_a_forked_script_is_the_script_run_by_exec(server, env, tmp_path: Path, shebang: str) -> None:
    script = _script(tmp_path, "report.py", REPORT, shebang)
    work = tmp_path / "work"
    work.mkdir()
    args = [str(script), "--ros-args", "-r", "__node:=a b"]
    executed = _exec(args, env, work, b"some input")
    forked = _fork(server, args, work, b"some input")
    assert forked == executed
    code, out, err = forked
    report = json.loads(out)
    assert code == 7 and err == b"to stderr\n"
    assert report["argv"] == args and report["name"] == "__main__" and report["own_group"]
    assert report["stdin"] == "some input"
    assert report["comm"] == ("python3\n" if shebang.startswith("#!/usr/bin/env") else "report.py\n")  # what the kernel executed
    assert report["cwd"] == str(work) and report["path0"] == str(script.parent)


def test_a_traceback_starts_at_the_script(server, env, tmp_path: Path) -> None:
    script = _script(tmp_path, "failing.py", FAILING)
    executed = _exec([str(script)], env, tmp_path)
    assert _fork(server, [str(script)], tmp_path) == executed
    assert executed[0] == 1 and executed[2].startswith(b"Traceback (most recent call last):\n  File \"" +
                                                       str(script).encode())


def test_ps_sees_the_forked_script_as_the_executed_one(server, env, tmp_path: Path) -> None:
    script = _script(tmp_path, "sleeper_node", SLEEPER)
    args = [str(script), "--ros-args", "-p", "rate:=2.0"]
    executed = subprocess.Popen(args, env=env, stdout=subprocess.PIPE, process_group=0)
    forked = _fork_sleeper(server, args, tmp_path)
    try:
        _ready(executed)
        seen, oracle = process_view(forked.pid), process_view(executed.pid)
        assert seen["comm"] == oracle["comm"] == "sleeper_node"
        assert seen["cmdline"] == oracle["cmdline"] == [sys.executable, *args]
        assert seen["pgid"] == forked.pid  # a group of its own, as asked
    finally:
        for process in (executed, forked):
            process.terminate()
    assert executed.wait(timeout=10) == forked.wait(timeout=10) == -signal.SIGTERM


def _threads(pid: int) -> list[str]:
    return sorted(Path(f"/proc/{pid}/task/{tid}/comm").read_text() for tid in os.listdir(f"/proc/{pid}/task"))


def test_a_forked_rclpy_process_has_the_threads_of_an_executed_one(server, env, tmp_path: Path) -> None:
    """rclpy's libraries start LTTng-UST's listener threads; the server re-makes them after each fork (as
    liblttng-ust-fork.so does), named after the process, as when it runs the script itself."""
    script = _script(tmp_path, "rclpy_node", "import rclpy.node\n" + SLEEPER)
    executed = subprocess.Popen([str(script)], env=env, stdout=subprocess.PIPE, process_group=0)
    forked = _fork_sleeper(server, [str(script)], tmp_path)
    try:
        _ready(executed)
        wait_until(lambda: _threads(forked.pid) == _threads(executed.pid), 5, "the same threads", period=0.1)
    finally:
        for process in (executed, forked):
            process.kill()
    executed.wait(timeout=10)
    forked.wait(timeout=10)


def test_a_fork_in_the_callers_group(server, tmp_path: Path) -> None:
    script = _script(tmp_path, "sleeper.py", SLEEPER)
    forked = _fork_sleeper(server, [str(script)], tmp_path, pgid=os.getpgrp())
    try:
        assert process_view(forked.pid)["pgid"] == os.getpgrp()
    finally:
        forked.kill()
    assert forked.wait(timeout=10) == -signal.SIGKILL


def _gone(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] in ("Z", "X")
    except OSError:
        return True


@pytest.mark.slow  # a server of its own: about half a second of CPU
def test_a_server_that_dies_takes_its_children_with_it(env, tmp_path: Path) -> None:
    process, client = _own_server(env)
    script = _script(tmp_path, "sleeper.py", SLEEPER)
    forked = _fork_sleeper(client, [str(script)], tmp_path)
    try:
        process.kill()
        assert forked.wait(timeout=10) == -signal.SIGKILL  # no supervision left: killed, not orphaned
        wait_until(lambda: _gone(forked.pid), 10, "the orphan to be gone", period=0.05)
        assert not client.alive
        with pytest.raises(OSError, match="the fork server"):
            client.popen([str(script)], subprocess.DEVNULL, subprocess.DEVNULL, None, str(tmp_path))
    finally:
        client.close()
        process.wait(timeout=10)


@pytest.mark.slow  # a server of its own: about half a second of CPU
def test_a_server_asked_for_nothing_ends_by_itself(env) -> None:
    process, channel = start_server(sys.executable, env, not_used=0.5)
    try:
        assert process.wait(timeout=30) == 0
    finally:
        channel.close()


@pytest.mark.slow  # a server of its own: about half a second of CPU
def test_a_server_ends_when_its_client_closes_and_stops_its_children(env, tmp_path: Path) -> None:
    process, client = _own_server(env)
    forked = _fork_sleeper(client, [str(_script(tmp_path, "sleeper.py", SLEEPER))], tmp_path)
    client.close()  # as when the client dies: nothing stopped the child
    assert process.wait(timeout=30) == 0
    wait_until(lambda: _gone(forked.pid), 10, "the child to be stopped", period=0.05)


def test_an_error_of_the_server_is_an_os_error(server, tmp_path: Path) -> None:
    script = _script(tmp_path, "report.py", REPORT)
    with pytest.raises(OSError, match="No such file or directory"):
        server.popen([str(script)], subprocess.DEVNULL, subprocess.DEVNULL, None, str(tmp_path / "missing"))
    with pytest.raises(OSError, match="not a Python script"):
        server.popen(["/bin/true"], subprocess.DEVNULL, subprocess.DEVNULL, None, str(tmp_path))


def test_which_scripts_a_server_takes(env, tmp_path: Path) -> None:
    assert script_interpreter(str(_script(tmp_path, "a", "", f"#!{sys.executable}")), env) == \
        (sys.executable, sys.executable)
    found = script_interpreter(str(_script(tmp_path, "b", "", "#!/usr/bin/env python3")), env)
    assert found is not None and found[0] == "python3" and os.path.realpath(found[1]) == \
        os.path.realpath(sys.executable)
    assert script_interpreter(str(_script(tmp_path, "c", "", "#!/usr/bin/env python3")), {"PATH": "/nowhere"}) \
        is None
    assert script_interpreter(str(_script(tmp_path, "d", "", f"#!{sys.executable} -u")), env) is None  # options
    assert script_interpreter(str(_script(tmp_path, "e", "", "#!/usr/bin/env -S python3 -u")), env) is None
    assert script_interpreter(str(_script(tmp_path, "f", "", f"#!{sys.executable}\r")), env) is None  # CRLF
    assert script_interpreter(str(_script(tmp_path, "g", "", "")), env) is None  # no #! line
    not_executable = _script(tmp_path, "h", "", f"#!{sys.executable}")
    not_executable.chmod(0o644)
    assert script_interpreter(str(not_executable), env) is None
    assert script_interpreter(str(tmp_path / "missing"), env) is None
    assert script_interpreter("/bin/true", env) is None  # an ELF file


def test_a_venvs_python_and_python3_share_a_server(tmp_path: Path) -> None:
    bin_dir = Path(sys.executable).parent
    names = [bin_dir / name for name in ("python", "python3") if (bin_dir / name).exists()]
    assert len({_server_key(str(name), {}) for name in names}) == 1
    assert _server_key(sys.executable, {}) != _server_key(sys.executable, {"ROS_DOMAIN_ID": "3"})
    if sys.prefix != sys.base_prefix:  # the interpreter the venv links to runs without the venv's packages
        assert _server_key(os.path.realpath(sys.executable), {}) != _server_key(sys.executable, {})


@pytest.mark.slow  # a server of its own: about half a second of CPU
def test_a_server_starts_for_the_second_process_that_can_use_it(env, tmp_path: Path) -> None:
    script = _script(tmp_path, "report.py", REPORT)
    warm = WarmStart()
    try:
        assert warm.server_for([str(script)], env) is None  # the first: exec, no server for one process
        assert warm.server_for(["/bin/true"], env) is None
        second = warm.server_for([str(script), "x"], env)
        assert second is not None and warm.server_for([str(script)], env) is second
        assert warm.server_for([str(script)], {**env, "OTHER": "1"}) is None  # another environment
        assert len(warm.pids) == 1
    finally:
        warm.close()


@pytest.mark.slow  # a server of its own: about half a second of CPU
def test_prepare_starts_servers_for_shared_interpreters_and_respawns(env, tmp_path: Path) -> None:
    script = _script(tmp_path, "report.py", REPORT)
    other = {**env, "OTHER": "1"}
    warm = WarmStart()
    try:
        warm.prepare([([str(script)], env, False), ([str(script), "x"], env, False),  # two share one
                      ([str(script)], other, True),  # a respawning process: its restarts share one
                      ([str(script)], {**env, "THIRD": "1"}, False),  # alone: exec
                      (["/bin/true"], env, False), (["/bin/true"], env, True)])
        assert len(warm.pids) == 2
        forked = warm.popen([str(script)], other, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL)
        assert forked is not None and forked.wait(timeout=30) == 7
        assert json.loads(forked.stdout.read())["own_group"]  # type: ignore[union-attr]
    finally:
        warm.close()
    for pid in warm.pids:
        assert not Path(f"/proc/{pid}").exists()


@pytest.mark.slow  # a server of its own: about half a second of CPU
def test_the_runners_event_loop_forks_what_it_can(env, tmp_path: Path) -> None:
    script = _script(tmp_path, "report.py", REPORT)
    process, channel = start_server(sys.executable, env)
    saved = dict(os.environ)
    os.environ.clear()
    os.environ.update(env)
    try:
        loop = warm_loop.install(os.dup(channel.fileno()), sys.executable)
        channel.close()

        async def run(args: list[str], **options) -> tuple[int, dict, int]:
            child = await asyncio.create_subprocess_exec(*args, stdout=subprocess.PIPE,
                                                         stdin=subprocess.DEVNULL, **options)
            out, _ = await child.communicate()
            return child.returncode, json.loads(out), child.pid  # type: ignore[return-value]

        code, report, pid = loop.run_until_complete(run([str(script), "a"], cwd=str(tmp_path)))
        assert code == 7 and report["argv"] == [str(script), "a"] and report["cwd"] == str(tmp_path)
        assert pid in loop.forked and not report["own_group"]  # the runner's group, as ros2 launch's nodes
        _, _, other = loop.run_until_complete(run([str(script)], env={**env, "OTHER": "1"}))
        _, _, new_session = loop.run_until_complete(run([str(script)], start_new_session=True))
        assert other not in loop.forked and new_session not in loop.forked  # started as usual
        loop.warm.close()
        loop.close()
    finally:
        asyncio.set_event_loop(None)
        os.environ.clear()
        os.environ.update(saved)
    assert process.wait(timeout=30) == 0


def test_a_forked_process_finds_rclpy_imported(server, env, tmp_path: Path) -> None:
    """Where a warm start saves its time (bench/launch_bench.py measures it)."""
    script = _script(tmp_path, "modules.py", "import sys\nprint('rclpy' in sys.modules)\n")
    assert _exec([str(script)], env, tmp_path)[1] == b"False\n"
    if subprocess.run([sys.executable, "-c", "import rclpy"], env=env, capture_output=True).returncode == 0:
        assert _fork(server, [str(script)], tmp_path)[1] == b"True\n"
