"""Real cache servers on localhost for the remote cache tests, each in a process of its own.

    PYTHONPATH=tests python -m helpers.remote_servers webdav ROOT [USER PASSWORD]   # wsgidav on cheroot
    PYTHONPATH=tests python -m helpers.remote_servers s3                            # moto's S3 server

Each binds a free port, prints it on its first line, and serves until terminated. ``webdav`` and
``s3`` below start one for a test and stop it by its PID.
"""

from __future__ import annotations

import contextlib
import os
import socket
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

from helpers.build import stop_process


def _serve_webdav(root: str, user: str | None, password: str | None) -> None:
    from cheroot import wsgi
    from wsgidav.wsgidav_app import WsgiDAVApp

    users = {user: {"password": password}} if user else {}
    config = {
        "provider_mapping": {"/": root},
        "simple_dc": {"user_mapping": {"*": users or True}},
        "http_authenticator": {"accept_basic": True, "accept_digest": False, "default_to_digest": False},
        "verbose": 0,
        "logging": {"enable": False},
    }
    server = wsgi.Server(("127.0.0.1", 0), WsgiDAVApp(config), numthreads=8)
    server.prepare()
    print(server.bind_addr[1], flush=True)
    server.serve()


def _serve_s3() -> None:
    from moto.server import ThreadedMotoServer

    server = ThreadedMotoServer(ip_address="127.0.0.1", port=0, verbose=False)
    server.start()
    print(server.get_host_and_port()[1], flush=True)
    threading.Event().wait()


@contextlib.contextmanager
def _server(*args: str) -> Iterator[int]:
    path = os.pathsep.join(filter(None, [str(Path(__file__).resolve().parents[1]), os.environ.get("PYTHONPATH")]))
    process = subprocess.Popen([sys.executable, "-m", "helpers.remote_servers", *args], stdout=subprocess.PIPE,
                               stderr=subprocess.DEVNULL, text=True, env={**os.environ, "PYTHONPATH": path})
    try:
        line = process.stdout.readline() if process.stdout else ""
        assert line.strip().isdigit(), f"the {args[0]} server did not start"
        yield int(line)
    finally:
        stop_process(process)


def webdav(root: Path, user: str | None = None, password: str | None = None) -> contextlib.AbstractContextManager[int]:
    """A WebDAV server keeping its files in ``root``; yields its port."""
    return _server("webdav", str(root), *([user, password] if user and password else []))


def s3() -> contextlib.AbstractContextManager[int]:
    """An S3-compatible server (moto); yields its port."""
    return _server("s3")


@contextlib.contextmanager
def silent_server() -> Iterator[int]:
    """A port that accepts connections and never answers (a server that hangs)."""
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(64)
    try:
        yield listener.getsockname()[1]
    finally:
        listener.close()


def free_port() -> int:
    """A port nothing listens on (a server that is down)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


if __name__ == "__main__":
    if sys.argv[1] == "webdav":
        _serve_webdav(sys.argv[2], *(sys.argv[3:5] if len(sys.argv) >= 5 else (None, None)))
    else:
        _serve_s3()
