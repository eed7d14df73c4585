"""roc's fork server, for warm starts (roc/launch/warm_start.py): an interpreter that has already started
Python, imported rclpy and loaded the type support every rclpy node loads, and that forks the Python
processes of a launched system from there. A forked process then runs its script as ``python SCRIPT
ARGS`` would: its own ``__main__``, ``sys.argv``, ``sys.path[0]``, standard streams, working directory,
process group, process name and command line (``/proc/PID/comm`` and ``cmdline``, as ``ps`` and ``pkill``
read them), and LTTng tracing re-armed after the fork as liblttng-ust-fork.so does it.

roc starts it as ``INTERPRETER forkserver.py FD IDLE PADDING`` with the environment of the processes it
serves (it serves no other). It runs on the nodes' interpreter, so it imports nothing of roc: the
standard library, then rclpy when that interpreter has it (without rclpy it still saves Python's start).

Protocol on the SOCK_SEQPACKET socket FD, one JSON message per packet:

- server -> client ``{"ready": N}`` once the N preloads are done;
- client -> server ``{"argv": [INTERPRETER, SCRIPT, ARG...], "executable": PATH, "cwd": DIR, "pgid": PGID}``
  with three file descriptors (the child's stdin, stdout, stderr); server -> client ``{"pid": PID}`` or
  ``{"error": TEXT}``;
- server -> client ``{"exited": PID, "code": CODE}`` when a child ends (CODE as subprocess's
  ``returncode``: negative for a signal).

It ends at the end of its socket (the client closed it, or died), sending SIGTERM to the children still
running (a client that died cannot stop them), or after IDLE seconds (0: never) when it has forked nothing
by then. PADDING makes its command line long enough for its children's.
"""

from __future__ import annotations

import os
import sys

if sys.path and os.path.realpath(sys.path[0]) == os.path.dirname(os.path.realpath(__file__)):
    del sys.path[0]  # this script's directory (roc/launch): none of its modules may shadow a node's imports

import ctypes  # noqa: E402
import io  # noqa: E402
import json  # noqa: E402
import selectors  # noqa: E402
import signal  # noqa: E402
import socket  # noqa: E402
import warnings  # noqa: E402

MAX_MESSAGE = 1 << 20
PR_SET_NAME = 15
# What every rclpy node loads while it starts: rclpy, and the type support of its built-in endpoints
# (/rosout, /parameter_events, the parameter services, the type description service).
PRELOAD_MODULES = ("rclpy", "rclpy.node", "rclpy.executors")
PRELOAD_TYPES = (
    ("rcl_interfaces.msg", "Log"), ("rcl_interfaces.msg", "ParameterEvent"),
    ("rcl_interfaces.srv", "DescribeParameters"), ("rcl_interfaces.srv", "GetParameters"),
    ("rcl_interfaces.srv", "GetParameterTypes"), ("rcl_interfaces.srv", "ListParameters"),
    ("rcl_interfaces.srv", "SetParameters"), ("rcl_interfaces.srv", "SetParametersAtomically"),
    ("type_description_interfaces.srv", "GetTypeDescription"),
)


def preload() -> int:
    """Import and load what the processes will need; how many of the preloads succeeded."""
    import importlib

    loaded = 0
    try:
        for name in PRELOAD_MODULES:
            importlib.import_module(name)
            loaded += 1
        from rclpy.type_support import check_for_type_support
    except Exception:  # noqa: BLE001 - no (working) rclpy for this interpreter: serve Python's start alone
        return loaded
    for module, name in PRELOAD_TYPES:
        try:
            check_for_type_support(getattr(importlib.import_module(module), name))
            loaded += 1
        except Exception:  # noqa: BLE001, S112 - an older or newer ROS without this interface
            continue
    try:  # setuptools' console scripts look their entry point up among the installed distributions
        import importlib.metadata

        importlib.metadata.distribution("roc-forkserver-index")  # indexes every sys.path entry, once
    except Exception:  # noqa: BLE001, S110 - not found, as intended
        pass
    return loaded


def lttng_fork_hooks():
    """LTTng-UST's fork handlers (before, after in the parent, after in the child) when rclpy loaded the
    library; None otherwise. Without them a forked process would have no tracing listener threads."""
    try:
        with open("/proc/self/maps") as maps:
            paths = {line.split()[-1] for line in maps if "/liblttng-ust" in line and ".so" in line}
    except OSError:
        return None
    for path in sorted(paths):
        library = ctypes.CDLL(path)
        for prefix in ("lttng_ust_", "ust_"):
            try:
                return tuple(getattr(library, prefix + name) for name in
                             ("before_fork", "after_fork_parent", "after_fork_child"))
            except AttributeError:
                continue
    return None


def fork(hooks) -> int:
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    signals = ctypes.create_string_buffer(128)  # a sigset_t: the mask LTTng restores after the fork
    if hooks:
        hooks[0](signals)
    pid = -1
    try:
        with warnings.catch_warnings():  # Python 3.12 warns of forking with threads: LTTng's, handled here
            warnings.simplefilter("ignore", DeprecationWarning)
            pid = os.fork()
    finally:
        if hooks:
            hooks[2 if pid == 0 else 1](signals)
    return pid


def set_process_name(name: str, title: str) -> None:
    """What ``ps``, ``top``, ``pgrep`` and ``pkill`` show: the name (comm) and the command line. The command
    line is written over this process's own (setproctitle's way: a title followed by a NUL, and a
    non-NUL last byte so that the kernel reads the title). The threads started before (LTTng's, re-made
    after the fork) are named too, as a new thread takes the name of the thread that makes it."""
    comm = name.encode(errors="replace")[:15]
    ctypes.CDLL(None).prctl(PR_SET_NAME, comm, 0, 0, 0)
    try:
        for thread in os.listdir("/proc/self/task"):
            with open(f"/proc/self/task/{thread}/comm", "wb") as thread_name:
                thread_name.write(comm)
    except OSError:
        pass
    try:
        with open("/proc/self/stat", "rb") as stat:
            fields = stat.read().rsplit(b")", 1)[1].split()
        start, end = int(fields[45]), int(fields[46])  # arg_start and arg_end, fields 48 and 49
    except (OSError, IndexError, ValueError):
        return
    size = end - start
    if size < 2:
        return
    data = title.encode(errors="replace")[:size - 2] + b"\0"
    ctypes.memmove(start, data + b" " * (size - len(data)), size)


def become(request: dict, fds: list[int]) -> str:
    """In the child, right after the fork: take on the process's streams, group, directory and names;
    the script to run."""
    for target, fd in enumerate(fds):
        os.dup2(fd, target)
    for fd in set(fds):
        if fd > 2:
            os.close(fd)
    try:
        os.setpgid(0, request["pgid"])
    except OSError:
        pass
    os.chdir(request["cwd"])
    argv = request["argv"]
    script = argv[1]
    # the kernel names a process after the file it executed: the script for '#!/usr/bin/python3', the
    # interpreter for '#!/usr/bin/env python3' (env executes it)
    set_process_name(os.path.basename(script) if "/" in argv[0] else argv[0], " ".join(argv))
    sys.argv = argv[1:]
    sys.orig_argv = list(argv)
    sys.executable = request["executable"]
    if not getattr(sys.flags, "safe_path", False):
        sys.path.insert(0, os.path.dirname(os.path.realpath(script)))
    for stream in (sys.stdout, sys.stderr):  # as Python sets them up for the new descriptors
        if isinstance(stream, io.TextIOWrapper) and not stream.write_through:  # else -u: nothing to change
            stream.reconfigure(line_buffering=stream is sys.stderr or stream.isatty())
    hide_own_frames(script)
    return script


def hide_own_frames(script: str) -> None:
    """An uncaught exception's traceback starts at the script, as when Python runs it (not here, nor in
    runpy)."""
    def hook(kind, value, traceback):
        head = traceback
        while head is not None and head.tb_frame.f_code.co_filename != script:
            head = head.tb_next
        if head is not None:
            value = value.with_traceback(head)  # what Python prints (not the hook's third argument)
        sys.__excepthook__(kind, value, value.__traceback__)

    sys.excepthook = hook


def check(request: dict, fds: list[int]) -> str:
    if len(fds) != 3:
        return f"expected 3 file descriptors, got {len(fds)}"
    if not os.path.isdir(request["cwd"]):
        return f"[Errno 2] No such file or directory: '{request['cwd']}'"
    return ""


def serve(channel: socket.socket, idle: float):
    """Fork on request until the socket ends; in a child, its (request, fds); in the server, None."""
    hooks = lttng_fork_hooks()
    selector = selectors.DefaultSelector()
    selector.register(channel, selectors.EVENT_READ)
    forked = 0

    def send(message: dict) -> None:
        channel.send(json.dumps(message).encode())

    while True:
        events = selector.select(timeout=idle if idle > 0 and not forked else None)
        if not events:
            return None  # never asked for anything: the system has no process for this interpreter
        for key, _mask in events:
            if key.fileobj is not channel:  # a child's pidfd: it ended
                selector.unregister(key.fileobj)
                os.close(key.fd)
                _pid, status = os.waitpid(key.data, 0)
                send({"exited": key.data, "code": os.waitstatus_to_exitcode(status)})
                continue
            try:
                data, fds, _flags, _address = socket.recv_fds(channel, MAX_MESSAGE, 3)
            except ConnectionError:
                data = b""
            if not data:
                for other in selector.get_map().values():
                    if other.fileobj is not channel:
                        os.kill(other.data, signal.SIGTERM)
                return None
            request = json.loads(data)
            problem = check(request, fds)
            pid = fork(hooks) if not problem else -1
            if pid == 0:
                for other in list(selector.get_map().values()):
                    if other.fileobj is not channel:
                        os.close(other.fd)
                selector.close()
                channel.close()
                return request, fds
            for fd in fds:
                os.close(fd)
            if problem:
                send({"error": problem})
                continue
            forked += 1
            selector.register(os.pidfd_open(pid), selectors.EVENT_READ, pid)
            send({"pid": pid})


def main(argv: list[str]):
    fd, idle = int(argv[0]), float(argv[1])
    channel = socket.socket(fileno=fd)
    channel.set_inheritable(False)
    set_process_name("roc-forkserver", f"{sys.executable} {os.path.abspath(__file__)}")
    try:
        loaded = preload()
        channel.send(json.dumps({"ready": loaded}).encode())
        return serve(channel, idle)
    except (BrokenPipeError, ConnectionError):
        return None  # the client went away


if __name__ == "__main__":
    _child = main(sys.argv[1:])
    if _child is None:
        sys.exit(0)
    _script = become(*_child)
    del _child
    import runpy

    runpy.run_path(_script, run_name="__main__")
