"""Processes of a roc.toml system on other hosts (``host = "DEST"``), started over SSH with the user's own
OpenSSH client, keys and ~/.ssh/config (``ROC_SSH_COMMAND`` replaces ``ssh``, as GIT_SSH_COMMAND does for
git, e.g. ``ssh -F ./ssh_config``).

Each process is one SSH session running roc's remote guard (roc/launch/remote_guard.py, sent through the
session with the guard module it uses: nothing of roc is installed there; the host needs python3, which
every ROS 2 installation has). roc writes a heartbeat into the session every second; the guard stops the
process when the session ends or stays silent (remote_guard.py: the bound). ssh's own keepalives
(ServerAliveInterval) tell roc within seconds when the connection is gone.

``check_hosts`` runs before anything starts, one engine task of kind ``host`` per host: can it be
reached, do its setup files source, has it every executable its processes need. ``RemoteProcess`` is
what the supervisor holds for a running remote process, with the parts of subprocess.Popen it uses.
"""

from __future__ import annotations

import base64
import json
import os
import shlex
import signal
import subprocess
import threading
from collections.abc import Callable, Mapping
from pathlib import Path

from roc.engine.process import TaskError
from roc.launch.remote_guard import HEARTBEAT_SECONDS, MARK
from roc.launch.system import HostSpec, ProcessSpec, System
from roc.ros.protocol import DISCOVERY_VARIABLES

HERE = Path(__file__).resolve().parent
# the modules sent to the host, in the order they are loaded there; the last one's main(spec) runs
MODULES = (("roc.launch.guard", HERE / "guard.py"), ("roc.launch.remote_guard", HERE / "remote_guard.py"))
SSH_OPTIONS = ("-T", "-o", "BatchMode=yes", "-o", "ConnectTimeout=10", "-o", "ServerAliveInterval=2",
               "-o", "ServerAliveCountMax=3")
# what roc gives a remote process of its own environment: the ROS settings a local process inherits
FORWARDED = (*DISCOVERY_VARIABLES, "RCUTILS_CONSOLE_OUTPUT_FORMAT", "RCUTILS_COLORIZED_OUTPUT",
             "RCUTILS_LOGGING_USE_STDOUT", "RCUTILS_LOGGING_BUFFERED_STREAM")
START_TIMEOUT = 60.0
CHECK_TIMEOUT = 60.0
SSH_FAILED = 255  # ssh's exit code when the connection fails or is lost
NO_PYTHON = 127

# Runs on the host, started by its login shell (sh, bash, zsh, fish, csh alike: one word of base64): reads
# "SIZE\n" and SIZE bytes of JSON (the modules' sources, the spec) from the session, loads the modules,
# runs the last one's main(spec). The rest of the session is the guard's.
_BOOTSTRAP = """import json, os, sys, types
def read(size):
    data = b""
    while len(data) < size:
        chunk = os.read(0, size - len(data))
        if not chunk:
            sys.exit(3)
        data += chunk
    return data
header = b""
while not header.endswith(b"\\n"):
    header += read(1)
load = json.loads(read(int(header)))
for name, source in load["modules"]:
    parts = name.split(".")
    for index in range(1, len(parts)):
        sys.modules.setdefault(".".join(parts[:index]), types.ModuleType(".".join(parts[:index])))
    module = sys.modules[name] = types.ModuleType(name)
    exec(compile(source, name.replace(".", "/") + ".py", "exec"), module.__dict__)
sys.exit(sys.modules[load["modules"][-1][0]].main(load["spec"]))
"""
REMOTE_COMMAND = ("exec python3 -S -E -c \"import base64;exec(base64.b64decode('"
                  + base64.b64encode(_BOOTSTRAP.encode()).decode() + "'))\"")


def ssh_command(destination: str) -> list[str]:
    """The ssh command line that runs roc's remote guard on ``destination``."""
    ssh = shlex.split(os.environ.get("ROC_SSH_COMMAND", "")) or ["ssh"]
    return [*ssh, *SSH_OPTIONS, "--", destination, REMOTE_COMMAND]


def payload(spec: dict) -> bytes:
    """What roc writes first into the session: the guard's modules and what it is to do."""
    modules = [[name, path.read_text()] for name, path in MODULES]
    data = json.dumps({"modules": modules, "spec": spec}).encode()
    return f"{len(data)}\n".encode() + data


def remote_environment(spec: ProcessSpec, environ: Mapping[str, str] = os.environ) -> dict[str, str]:
    """What roc sets for a remote process over its host's environment (after the setup files): the ROS
    settings of roc's own environment, then the process's ``env``."""
    return {**{name: environ[name] for name in FORWARDED if name in environ}, **spec.env}


def _ssh_failure(destination: str, code: int, stderr: str) -> str:
    lines = [line for line in stderr.strip().splitlines() if not line.startswith(MARK)]
    said = lines[-1].strip() if lines else f"ssh exited with code {code}"
    if code == NO_PYTHON:
        return f"host '{destination}' has no python3 on its PATH (roc's guard there needs it): {said}"
    return f"host '{destination}' cannot be reached: {said}"


def _events(stderr: str) -> list[dict]:
    return [json.loads(line[len(MARK):]) for line in stderr.splitlines() if line.startswith(MARK)]


def check_host(host: HostSpec, specs: list[ProcessSpec], env: dict[str, str]) -> dict:
    """Whether ``host`` can be reached, its setup files source and it has each process's executable:
    {"found": {"PKG/EXECUTABLE": its path there}, "cwd": where the processes start there}; raises TaskError
    saying what is wrong."""
    spec = {"mode": "check", "setup": host.setup,
            "executables": sorted({(s.package, s.executable) for s in specs})}
    try:
        done = subprocess.run(ssh_command(host.destination), input=payload(spec), capture_output=True, env=env,
                              timeout=CHECK_TIMEOUT)
    except subprocess.TimeoutExpired:
        raise TaskError(f"host '{host.destination}' did not answer within {CHECK_TIMEOUT:g} s") from None
    except OSError as error:
        raise TaskError(f"cannot run ssh: {error.strerror}") from None
    stderr = done.stderr.decode(errors="replace")
    checked = [event for event in _events(stderr) if event["event"] == "checked"]
    if not checked:
        raise TaskError(_ssh_failure(host.destination, done.returncode, stderr))
    result = checked[0]
    where = f"host '{host.destination}'"
    if result["error"]:
        raise TaskError(f"{where}: {result['error']} ({host.where})")
    if result["missing"]:
        users = ", ".join(sorted({s.where for s in specs}))
        raise TaskError(f"{where}: {'; '.join(result['missing'])} ({users})")
    return result


def check_hosts(system: System, env: dict[str, str]) -> dict[str, dict]:
    """Every host of the system checked at once (engine tasks of kind ``host``) before anything starts:
    what ``check_host`` found, by host; one RocError line naming what is wrong."""
    from roc.engine.events import Event, TaskFailed
    from roc.engine.executor import execute
    from roc.engine.ready import Task
    from roc.errors import RocError

    found: dict[str, dict] = {}
    failures: list[str] = []

    def task(host: HostSpec) -> Task:
        specs = [spec for spec in system.remote() if spec.host == host.destination]

        def action(_context) -> None:
            found[host.destination] = check_host(host, specs, env)
        return Task(name=host.destination, dependencies=set(), kind="host", action=action)

    def failed(event: Event) -> None:
        if isinstance(event, TaskFailed):
            failures.append(event.reason)

    used = {spec.host for spec in system.remote()}
    tasks = [task(host) for name, host in system.hosts.items() if name in used]
    if tasks and execute(tasks, [failed], workers=0, continue_on_error=True, kind="host").interrupted:
        raise KeyboardInterrupt  # Ctrl+C while checking: nothing has started
    if failures:
        raise RocError(f"{system.path}: [launch.{system.name}]: {'; '.join(failures)}")
    return found


class RemoteProcess:
    """A process on another host as roc's supervisor sees a subprocess.Popen: ``pid`` (its PID there),
    ``args`` (its command line there), ``stdout`` (its output), ``poll``, ``wait`` and ``send_signal``
    (to its process group there). Behind it: ssh, running roc's remote guard."""

    def __init__(self, host: HostSpec, spec: ProcessSpec, token: str, env: dict[str, str],
                 note: Callable[[str], None], usage: Callable[[float, int], None]):
        self.destination = host.destination
        self.note, self.usage = note, usage
        self.pid = 0
        self.args: list[str] = []
        self.returncode: int | None = None
        self._code: int | None = None  # the process's exit code, as the guard reported it
        self._reason = ""  # why the guard stopped it, when it did on its own
        self._error = ""
        self._ssh_lines: list[str] = []
        self._started = threading.Event()
        self._lock = threading.Lock()  # writes into the session
        self._finishing = threading.Lock()
        start = {"mode": "run", "setup": host.setup, "package": spec.package, "executable": spec.executable,
                 "arguments": [*spec.arguments, *spec.ros_arguments()], "env": remote_environment(spec),
                 "token": token}
        try:  # a process group of its own: the terminal's Ctrl+C is roc's to pass on
            self.ssh = subprocess.Popen(ssh_command(self.destination), stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, process_group=0)
        except OSError as error:
            raise TaskError(f"cannot run ssh: {error.strerror}") from None
        self.stdout = self.ssh.stdout
        self._control = threading.Thread(target=self._read_control, name=f"roc-ssh-{spec.label}", daemon=True)
        self._control.start()
        self._write(payload(start))
        threading.Thread(target=self._heartbeat, name=f"roc-heartbeat-{spec.label}", daemon=True).start()

    def wait_started(self, timeout: float = START_TIMEOUT) -> None:
        """Until the guard has started the process; TaskError when it could not (or ssh failed)."""
        if not self._started.wait(timeout):
            self.kill()
            raise TaskError(f"host '{self.destination}' did not start the process within {timeout:g} s")
        if not self.pid:
            self.ssh.wait()
            self._control.join()
            if self._error:
                raise TaskError(f"on host '{self.destination}': {self._error}")
            raise TaskError(_ssh_failure(self.destination, self.ssh.returncode or 0, "\n".join(self._ssh_lines)))

    def _write(self, data: bytes) -> None:
        with self._lock:
            try:
                assert self.ssh.stdin is not None
                self.ssh.stdin.write(data)
                self.ssh.stdin.flush()
            except (OSError, ValueError):  # ssh has ended
                pass

    def _heartbeat(self) -> None:
        while True:
            try:
                self.ssh.wait(timeout=HEARTBEAT_SECONDS)
                return
            except subprocess.TimeoutExpired:
                self._write(b"\n")

    def _read_control(self) -> None:
        """The guard's events and ssh's own messages, from ssh's standard error."""
        assert self.ssh.stderr is not None
        for raw in self.ssh.stderr:
            line = raw.decode(errors="replace").rstrip("\n")
            if not line.startswith(MARK):
                self._ssh_lines.append(line)
                if self.pid:
                    self.note(f"ssh: {line}")
                continue
            try:
                event = json.loads(line[len(MARK):])
            except ValueError:
                continue
            if event["event"] == "started":
                self.pid, self.args = event["pid"], event["cmd"]
                self._started.set()
            elif event["event"] == "usage":
                self.usage(event["cpu"], event["rss"])
            elif event["event"] == "exited":
                self._code, self._reason = event["code"], event["reason"]
            elif event["event"] == "error":
                self._error = event["message"]
        self._started.set()

    def _finish(self) -> int:
        ssh_code = self.ssh.wait()
        self._control.join()
        with self._finishing:
            if self.returncode is None:
                if self._code is None:
                    how = f"exit code {ssh_code}" if ssh_code >= 0 else f"killed by {signal.Signals(-ssh_code).name}"
                    self.note(f"the connection to '{self.destination}' was lost (ssh {how}): the process there is "
                              "stopped by roc's guard on that host")
                elif self._reason:
                    self.note(f"roc's guard on '{self.destination}' stopped the process: {self._reason}")
                self.returncode = self._code if self._code is not None else SSH_FAILED
        return self.returncode

    def poll(self) -> int | None:
        return None if self.ssh.poll() is None else self._finish()

    def wait(self, timeout: float | None = None) -> int:
        self.ssh.wait(timeout)  # raises subprocess.TimeoutExpired as Popen.wait does
        return self._finish()

    def send_signal(self, signum: int) -> None:
        """To the process's group on its host, through the guard."""
        self._write(f"signal {int(signum)}\n".encode())

    def kill(self) -> None:
        """End the session (the guard then stops the process)."""
        if self.ssh.poll() is None:
            self.ssh.kill()
