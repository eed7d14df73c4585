"""Warm starts for launch files: the launch runner's asyncio event loop forks, through the run's fork
servers (roc/launch/warm_start.py), each process the launch library starts that one of them can fork; the
library gets an ordinary subprocess transport (asyncio's own, over the forked process), and every other
process starts as before."""

from __future__ import annotations

import asyncio
import os
import socket
from asyncio import base_subprocess

from roc.launch.warm_start import ForkServer, WarmStart

# what the launch library passes besides the streams; any other option (a new session, pass_fds...) execs
FORKABLE_OPTIONS = {"cwd", "env", "close_fds"}


class ForkedTransport(base_subprocess.BaseSubprocessTransport):
    def _start(self, args, shell, stdin, stdout, stderr, bufsize, server=None, cwd=None, **_options):
        # the launch library's processes share the runner's process group, as under ros2 launch
        self._proc = server.popen(list(args), stdin, stdout, stderr, cwd, pgid=os.getpgrp())
        loop = self._loop

        def exited(code: int) -> None:
            try:
                loop.call_soon_threadsafe(self._process_exited, code)
            except RuntimeError:  # the loop is closed: the run is over
                pass

        self._proc.add_exit_callback(exited)


class WarmLoop(asyncio.SelectorEventLoop):
    def __init__(self, warm: WarmStart):
        super().__init__()
        self.warm = warm
        self.forked: set[int] = set()  # the PIDs of the processes it forked

    async def _make_subprocess_transport(self, protocol, args, shell, stdin, stdout, stderr, bufsize,
                                         extra=None, **options):
        env = options.get("env")
        server = None
        if not shell and not set(options) - FORKABLE_OPTIONS:
            server = self.warm.server_for(list(args), os.environ if env is None else env)
        if server is not None:
            waiter = self.create_future()
            try:
                transport = ForkedTransport(self, protocol, args, shell, stdin, stdout, stderr, bufsize,
                                            waiter=waiter, extra=extra, server=server, cwd=options.get("cwd"))
            except OSError:
                pass  # the server could not: start it as usual
            else:
                self.forked.add(transport.get_pid())
                try:
                    await waiter
                except (SystemExit, KeyboardInterrupt):
                    raise
                except BaseException:
                    transport.close()
                    await transport._wait()
                    raise
                return transport
        return await super()._make_subprocess_transport(protocol, args, shell, stdin, stdout, stderr, bufsize,
                                                        extra=extra, **options)


def install(fd: int, interpreter: str) -> WarmLoop:
    """The runner's event loop, with the server roc started for the runner's interpreter and environment
    (its socket ``fd``, inherited from roc)."""
    os.set_inheritable(fd, False)  # the processes started as usual must not hold the server's socket
    warm = WarmStart()
    warm.adopt(ForkServer(socket.socket(fileno=fd), interpreter, os.environ))
    loop = WarmLoop(warm)
    asyncio.set_event_loop(loop)
    return loop
