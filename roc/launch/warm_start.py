"""Warm start: ``roc launch`` forks the Python processes of a system from a fork server
(roc/launch/forkserver.py), an interpreter that has already started Python, imported rclpy and loaded the
type support every rclpy node loads, instead of starting Python afresh for each of them. A node then takes
about 20 ms of CPU to start instead of about 300 ms (docs/commands/launch.md, "Warm start").

A server serves one interpreter and one environment. A process is forked when its executable is a Python
script whose ``#!`` line names the server's interpreter (``#!/usr/bin/python3`` or ``#!/usr/bin/env
python3``, without options) and its environment is exactly the server's; any other process is started as
before (exec), and so is every process when its server cannot start or has ended.

Used through ``WarmStart``, the servers of a run, by roc's supervisor (roc.toml systems) and by the launch
runner (launch files, roc/launch/warm_loop.py); a ``ForkServer`` is the client's end of one server's socket.
"""

from __future__ import annotations

import json
import os
import queue
import shutil
import signal
import socket
import subprocess
import threading
from collections.abc import Callable, Mapping

SERVER_SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "forkserver.py")
TITLE_ROOM = 4096  # bytes of the server's command line, which its children's command lines are written over
READY_TIMEOUT = 30.0  # seconds a start waits for the server's preloads (a slow machine), else it execs
REPLY_TIMEOUT = 10.0
MAX_MESSAGE = 1 << 20
NOT_USED_SECONDS = 30.0  # a server that forked nothing in this time ends (a launch file of C++ nodes)


def script_interpreter(path: str, env: Mapping[str, str]) -> tuple[str, str] | None:
    """The interpreter an executable script's ``#!`` line names, as (the name the interpreter is started
    with, its absolute path): ``#!/usr/bin/python3`` or ``#!/usr/bin/env python3`` (found on ``env``'s
    PATH), without options; None for anything else."""
    try:
        with open(path, "rb") as handle:
            head = handle.read(256)
    except OSError:
        return None
    if not head.startswith(b"#!") or not os.access(path, os.X_OK):
        return None
    line = head[2:].split(b"\n", 1)[0]
    if b"\r" in line:  # a file with Windows line ends: its interpreter is not found, as by exec
        return None
    words = line.decode(errors="surrogateescape").split()
    if len(words) == 2 and os.path.basename(words[0]) == "env" and "/" not in words[1]:
        found = shutil.which(words[1], path=env.get("PATH", os.defpath))
        return (words[1], os.path.abspath(found)) if found else None
    if len(words) == 1 and words[0].startswith("/"):
        return words[0], words[0]
    return None


def _server_key(interpreter: str, env: Mapping[str, str]) -> tuple:
    """What one server serves: one interpreter (the same file in the same directory: a venv's ``python``
    and ``python3`` are one, the base interpreter the venv links to is another) and one environment."""
    return (os.path.realpath(os.path.dirname(interpreter)), os.path.realpath(interpreter),
            tuple(sorted(env.items())))


def start_server(interpreter: str, env: Mapping[str, str], not_used: float = 0.0) -> tuple[subprocess.Popen,
                                                                                             socket.socket]:
    """A fork server for ``interpreter`` and ``env``, in a process group of its own (the terminal's signals
    are roc's to pass on); its process and the client's end of its socket. ``not_used``: seconds after
    which it ends if it forked nothing (0: never). Raises OSError."""
    ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    try:
        process = subprocess.Popen([interpreter, SERVER_SCRIPT, str(theirs.fileno()), str(not_used), "." * TITLE_ROOM],
                                   env=dict(env), stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL, pass_fds=(theirs.fileno(),), process_group=0)
    except OSError:
        ours.close()
        raise
    finally:
        theirs.close()
    return process, ours


def wait_for_server(process: subprocess.Popen) -> None:
    """Wait for a server to leave (it does at the end of its socket), else kill it."""
    try:
        process.wait(timeout=5.0)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()


class ForkedProcess:
    """A process forked by a fork server, with what roc and asyncio use of subprocess.Popen: ``pid``,
    ``args``, the pipes, ``returncode``, ``poll``, ``wait``, ``send_signal``, ``terminate`` and ``kill``.
    Its exit comes from the server (its parent)."""

    def __init__(self, args: list[str]):
        self.args = args
        self.pid = 0
        self.returncode: int | None = None
        self.stdin = self.stdout = self.stderr = None
        self._ended = threading.Event()
        self._lock = threading.Lock()
        self._callbacks: list[Callable[[int], None]] = []

    def exited(self, code: int) -> None:
        with self._lock:
            if self._ended.is_set():
                return
            self.returncode = code
            self._ended.set()
            callbacks, self._callbacks = self._callbacks, []
        for callback in callbacks:
            callback(code)

    def add_exit_callback(self, callback: Callable[[int], None]) -> None:
        """``callback(returncode)`` once the process has ended (at once if it has)."""
        with self._lock:
            if not self._ended.is_set():
                self._callbacks.append(callback)
                return
        callback(self.returncode)  # type: ignore[arg-type]

    def poll(self) -> int | None:
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        if not self._ended.wait(timeout):
            raise subprocess.TimeoutExpired(self.args, timeout or 0.0)
        return self.returncode  # type: ignore[return-value]

    def send_signal(self, signum: int) -> None:
        if self.returncode is None:
            try:
                os.kill(self.pid, signum)
            except ProcessLookupError:
                pass

    def terminate(self) -> None:
        self.send_signal(signal.SIGTERM)

    def kill(self) -> None:
        self.send_signal(signal.SIGKILL)


def _child_streams(stdin, stdout, stderr) -> tuple[list[int], dict[int, int], list[int]]:
    """The child's three descriptors from Popen-style arguments (PIPE, DEVNULL, STDOUT for stderr, a
    descriptor or file, None: this process's own); this side's ends of the pipes by stream number; the
    descriptors made here for the child, to close once it has them."""
    child: list[int] = []
    ours: dict[int, int] = {}
    made: list[int] = []
    for number, stream in enumerate((stdin, stdout, stderr)):
        if stream == subprocess.PIPE:
            read, write = os.pipe()
            ours[number], given = (write, read) if number == 0 else (read, write)
            made.append(given)
        elif stream == subprocess.DEVNULL:
            given = os.open(os.devnull, os.O_RDWR)
            made.append(given)
        elif stream == subprocess.STDOUT and number == 2:
            given = child[1]
        elif stream is None:
            given = number
        else:
            given = stream if isinstance(stream, int) else stream.fileno()
        child.append(given)
    return child, ours, made


class ForkServer:
    """The client's end of one fork server's socket: starts processes there, and learns of their ends on a
    thread of its own. When the server ends, the processes it forked are killed (they have lost their
    supervision) and reported with -SIGKILL."""

    def __init__(self, channel: socket.socket, interpreter: str, env: Mapping[str, str]):
        self.interpreter = interpreter
        self.env = dict(env)
        self._channel = channel
        self._ready = threading.Event()
        self._gone = threading.Event()
        self._request_lock = threading.Lock()  # one start at a time
        self._table_lock = threading.Lock()
        self._replies: queue.Queue[dict] = queue.Queue()
        self._starting: ForkedProcess | None = None
        self._children: dict[int, ForkedProcess] = {}
        self._reader = threading.Thread(target=self._read, name="roc-forkserver", daemon=True)
        self._reader.start()

    @property
    def alive(self) -> bool:
        return not self._gone.is_set()

    def popen(self, args: list[str], stdin=None, stdout=None, stderr=None, cwd: str | None = None,
              pgid: int = 0) -> ForkedProcess:
        """Fork ``args`` (a script this server serves, and its arguments) in process group ``pgid`` (0: one
        of its own); the streams as subprocess.Popen takes them. Raises OSError when the server cannot."""
        if not self._ready.wait(READY_TIMEOUT):
            self.close()  # stuck in its preloads: the processes start as usual
        if self._gone.is_set():
            raise OSError("the fork server is not running")
        child, ours, made = _child_streams(stdin, stdout, stderr)
        process = ForkedProcess(list(args))
        interpreter = script_interpreter(args[0], self.env)
        if interpreter is None:
            raise OSError(f"{args[0]}: not a Python script")
        request = {"argv": [interpreter[0], *args], "executable": interpreter[1],
                   "cwd": os.path.abspath(cwd or os.getcwd()), "pgid": pgid}
        try:
            with self._request_lock:
                self._starting = process
                socket.send_fds(self._channel, [json.dumps(request).encode()], child)
                reply = self._replies.get(timeout=REPLY_TIMEOUT)
        except (OSError, queue.Empty) as error:
            reply = {"error": str(error) or "the fork server did not answer"}
        finally:
            for fd in made:
                os.close(fd)
        if "error" in reply:
            for fd in ours.values():
                os.close(fd)
            raise OSError(reply["error"])
        process.stdin = os.fdopen(ours[0], "wb", buffering=0) if 0 in ours else None  # type: ignore[assignment]
        process.stdout = os.fdopen(ours[1], "rb", buffering=0) if 1 in ours else None  # type: ignore[assignment]
        process.stderr = os.fdopen(ours[2], "rb", buffering=0) if 2 in ours else None  # type: ignore[assignment]
        return process

    def _read(self) -> None:
        try:
            while data := self._channel.recv(MAX_MESSAGE):
                message = json.loads(data)
                if "ready" in message:
                    self._ready.set()
                elif "exited" in message:
                    with self._table_lock:
                        ended = self._children.pop(message["exited"], None)
                    if ended is not None:
                        ended.exited(message["code"])
                else:
                    if "pid" in message and self._starting is not None:
                        self._starting.pid = message["pid"]
                        with self._table_lock:
                            self._children[message["pid"]] = self._starting
                    self._replies.put(message)
        except (OSError, ValueError):
            pass
        self._gone.set()
        self._ready.set()
        self._replies.put({"error": "the fork server ended"})
        with self._table_lock:
            orphans, self._children = list(self._children.values()), {}
        for orphan in orphans:
            orphan.kill()
            orphan.exited(-signal.SIGKILL)

    def close(self) -> None:
        """End the server (it leaves at the end of its socket)."""
        try:
            self._channel.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self._reader.join(timeout=5.0)
        self._channel.close()


class WarmStart:
    """The fork servers of a run, one per interpreter and environment (see ``_server_key``): those made
    up front (``prepare``, or a server roc started and handed over: ``adopt``), and one more for any
    interpreter and environment that a second process asks for (the first is started as usual)."""

    def __init__(self) -> None:
        self._servers: dict[tuple, ForkServer] = {}
        self._processes: list[subprocess.Popen] = []
        self._asked: dict[tuple, int] = {}
        self._lock = threading.Lock()

    def adopt(self, server: ForkServer) -> None:
        self._servers[_server_key(server.interpreter, server.env)] = server

    def _start(self, key: tuple, interpreter: str, env: Mapping[str, str]) -> ForkServer | None:
        try:
            process, channel = start_server(interpreter, env)
        except OSError:
            return None
        self._processes.append(process)
        server = self._servers[key] = ForkServer(channel, interpreter, env)
        return server

    def prepare(self, starts: list[tuple[list[str], dict[str, str], bool]]) -> None:
        """Start now the servers for ``starts`` (each process's command, environment and whether it
        respawns): one for each interpreter and environment that two processes share, or a respawning one."""
        weights: dict[tuple, int] = {}
        for command, env, respawns in starts:
            interpreter = script_interpreter(command[0], env) if command else None
            if interpreter is not None:
                key = _server_key(interpreter[1], env)
                weights[key] = weights.get(key, 0) + (2 if respawns else 1)
                if weights[key] >= 2 and key not in self._servers:
                    self._start(key, interpreter[1], env)

    @property
    def pids(self) -> list[int]:
        return [process.pid for process in self._processes]

    def server_for(self, args: list[str], env: Mapping[str, str]) -> ForkServer | None:
        """The server that can fork ``args`` (a script and its arguments) with ``env``, if any."""
        interpreter = script_interpreter(args[0], env) if args else None
        if interpreter is None:
            return None
        key = _server_key(interpreter[1], env)
        with self._lock:
            server = self._servers.get(key)
            if server is None:
                self._asked[key] = self._asked.get(key, 0) + 1
                if self._asked[key] >= 2:
                    server = self._start(key, interpreter[1], env)
        return server if server is not None and server.alive else None

    def popen(self, args: list[str], env: dict[str, str], **streams) -> ForkedProcess | None:
        """``args`` forked in a process group of its own, or None when no server can."""
        server = self.server_for(args, env)
        if server is None:
            return None
        try:
            return server.popen(args, pgid=0, **streams)
        except OSError:
            return None

    def close(self) -> None:
        for server in self._servers.values():
            server.close()
        for process in self._processes:
            wait_for_server(process)
        self._servers, self._processes = {}, []
