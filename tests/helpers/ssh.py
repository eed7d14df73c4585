"""What the tests of roc launch's processes on other hosts and bench/launch_remote_bench.py share.

- ``ssh_server``: an SSH server on 127.0.0.1, Debian's openssh-server (``sshd``, installed by
  ``ROC_SETUP_TEST_TOOLS=1 bash scripts/setup.sh``) started with a configuration of its own in the test's
  directory, a throwaway host key and user key, on a free port; never the system's sshd. Its ``ssh_config``
  names it ``robot`` (through a relay that can cut the connection without closing it, as a pulled cable
  does), ``robot-direct``, and ``nowhere`` (a port nothing listens on). roc uses it through
  ``ROC_SSH_COMMAND="ssh -F ssh_config"`` (``SshServer.env()``).
- ``write_pair``: a roc.toml system of a local talker and a listener on another host.
- what a test reads of a process in /proc: ``alive``, ``ancestors``, ``sshd_session``.
"""

from __future__ import annotations

import contextlib
import getpass
import os
import select
import shutil
import socket
import subprocess
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from helpers.build import stop_process

PAIR = """
[launch.pair.hosts."robot"]
setup = "{setup}"

[[launch.pair.process]]
package = "roc_launch_demo"
executable = "talker"
namespace = "local"
parameters = {{ rate = 5.0 }}

[[launch.pair.process]]
package = "roc_launch_demo"
executable = "listener"
name = "far_listener"
namespace = "local"
host = "{host}"
env = {{ ROC_TEST_MARK = "far" }}
respawn = {respawn}
respawn-delay = 0.2
after = ["process local/talker started"]
"""
REMOTE = "robot:local/far_listener"  # the remote process, as roc's output names it


def write_pair(directory: Path, prefix: Path, host: str = "robot", respawn: bool = False) -> None:
    """``[launch.pair]`` in ``directory``/roc.toml: roc_launch_demo's talker here, its listener on ``host``,
    which sources the setup.bash of ``prefix``'s install."""
    (directory / "roc.toml").write_text(PAIR.format(setup=prefix.parent / "setup.bash", host=host,
                                                    respawn=str(respawn).lower()))


def _stat(pid: int) -> list[str]:
    return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()


def alive(pid: int) -> bool:
    try:
        return _stat(pid)[0] not in ("Z", "X")
    except OSError:
        return False


def ancestors(pid: int) -> list[int]:
    """A process's ancestors, nearest first."""
    found = []
    while pid > 1:
        pid = int(_stat(pid)[1])
        found.append(pid)
    return found


def comm(pid: int) -> str:
    return Path(f"/proc/{pid}/comm").read_text().strip()


def sshd_session(pid: int) -> int:
    """The sshd process on the server's side of a remote process's session (its nearest sshd ancestor)."""
    return next(ancestor for ancestor in ancestors(pid) if comm(ancestor) == "sshd")


SSHD = shutil.which("sshd") or next((p for p in ("/usr/sbin/sshd",) if os.access(p, os.X_OK)), None)


def require_sshd() -> str:
    if SSHD is None:
        message = "sshd is not installed (ROC_SETUP_TEST_TOOLS=1 bash scripts/setup.sh installs openssh-server)"
        if os.environ.get("CI"):
            pytest.fail(f"{message}: CI must run these tests")
        pytest.skip(message)
    return SSHD


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class Relay:
    """127.0.0.1:``port`` forwarded to ``target``; ``cut()`` stops every connection open now from carrying
    anything either way, without closing it (nobody is told: a network cut), while new ones go through."""

    def __init__(self, target: int):
        self.target = target
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.closed = threading.Event()
        self._connections: list[tuple[socket.socket, socket.socket, threading.Event]] = []
        self._lock = threading.Lock()
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self) -> None:
        while not self.closed.is_set():
            try:
                client, _ = self.listener.accept()
            except OSError:
                return
            server = socket.create_connection(("127.0.0.1", self.target))
            frozen = threading.Event()
            with self._lock:
                self._connections.append((client, server, frozen))
            for source, sink in ((client, server), (server, client)):
                threading.Thread(target=self._pump, args=(source, sink, frozen), daemon=True).start()

    def _pump(self, source: socket.socket, sink: socket.socket, frozen: threading.Event) -> None:
        while not self.closed.is_set():
            if frozen.is_set():
                self.closed.wait()  # read nothing more, close nothing: the peers wait in vain
                return
            try:
                readable, _, _ = select.select([source], [], [], 0.1)
                if not readable or frozen.is_set():
                    continue
                data = source.recv(65536)
                if data:
                    sink.sendall(data)
                    continue
                sink.shutdown(socket.SHUT_WR)  # the peer closed: tell the other one
            except OSError:  # reset: the other one is told too
                with contextlib.suppress(OSError):
                    sink.shutdown(socket.SHUT_RDWR)
            return

    def cut(self) -> None:
        with self._lock:
            for _, _, frozen in self._connections:
                frozen.set()

    def close(self) -> None:
        self.closed.set()
        self.listener.close()
        with self._lock:
            for client, server, _ in self._connections:
                client.close()
                server.close()


class SshServer:
    def __init__(self, directory: Path, port: int, relay: Relay):
        self.directory, self.port, self.relay = directory, port, relay
        self.config = directory / "ssh_config"

    def env(self) -> dict[str, str]:
        return {"ROC_SSH_COMMAND": f"ssh -F {self.config}"}


def _wait_for_port(port: int, process: subprocess.Popen, log: Path, timeout: float = 20.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        assert process.poll() is None, f"sshd ended: {log.read_text()}"
        with contextlib.suppress(OSError), socket.create_connection(("127.0.0.1", port), timeout=1):
            return
        time.sleep(0.05)
    raise AssertionError(f"sshd did not listen on port {port} within {timeout:g} s")


@contextlib.contextmanager
def ssh_server(directory: Path) -> Iterator[SshServer]:
    """sshd on a free port of 127.0.0.1, with keys and an ssh_config of its own in ``directory``."""
    sshd = require_sshd()
    directory.mkdir(parents=True, exist_ok=True)
    for key in ("host_key", "user_key"):
        subprocess.run(["ssh-keygen", "-q", "-t", "ed25519", "-N", "", "-f", str(directory / key)], check=True)
    shutil.copy(directory / "user_key.pub", directory / "authorized_keys")
    if os.geteuid() == 0:  # sshd started by root needs its privilege separation directory (systemd makes it)
        os.makedirs("/run/sshd", mode=0o755, exist_ok=True)
    port = free_port()
    (directory / "sshd_config").write_text(
        f"ListenAddress 127.0.0.1\nPort {port}\nHostKey {directory}/host_key\n"
        f"AuthorizedKeysFile {directory}/authorized_keys\nPidFile none\nUsePAM no\nStrictModes no\n"
        "PermitRootLogin prohibit-password\nPasswordAuthentication no\nKbdInteractiveAuthentication no\n"
        "LogLevel ERROR\n")
    log = directory / "sshd.log"
    with open(log, "w") as output:
        process = subprocess.Popen([sshd, "-f", str(directory / "sshd_config"), "-D", "-e"], stdin=subprocess.DEVNULL,
                                   stdout=output, stderr=subprocess.STDOUT)
    relay = Relay(port)
    try:
        _wait_for_port(port, process, log)
        common = (f"  User {getpass.getuser()}\n  IdentityFile {directory}/user_key\n  IdentitiesOnly yes\n"
                  "  StrictHostKeyChecking no\n  UserKnownHostsFile /dev/null\n  LogLevel ERROR\n")
        (directory / "ssh_config").write_text(
            f"Host robot\n  HostName 127.0.0.1\n  Port {relay.port}\n{common}"
            f"Host robot-direct\n  HostName 127.0.0.1\n  Port {port}\n{common}"
            f"Host nowhere\n  HostName 127.0.0.1\n  Port {free_port()}\n{common}")
        yield SshServer(directory, port, relay)
    finally:
        relay.close()
        import psutil

        with contextlib.suppress(psutil.Error):  # the sessions a failing test left open
            for session in psutil.Process(process.pid).children(recursive=True):
                session.kill()
        stop_process(process)
