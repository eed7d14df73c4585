"""One log file per process of a launched system, ``<run directory>/<process name>.log``: everything the
process wrote (stdout and stderr as they came), with a ``[roc]`` line when it starts and when it ends.

The run directory is ``log/launch_<time>/`` at the workspace root, as for builds; outside a workspace it is
where ros2 launch writes its logs, named as the launch library names its own (``ros_log_directory``,
``new_ros_run_directory``)."""

from __future__ import annotations

import datetime
import os
import socket
import time
from pathlib import Path
from typing import TextIO


def ros_log_directory() -> Path:
    """Where ROS 2 writes logs, by the launch library's (and rcutils') rule: $ROS_LOG_DIR, else
    $ROS_HOME/log, else ~/.ros/log (``~`` expanded, the path normalized)."""
    directory = os.environ.get("ROS_LOG_DIR") or os.path.join(os.environ.get("ROS_HOME") or "~/.ros", "log")
    return Path(os.path.normpath(os.path.expanduser(directory)))


def new_ros_run_directory(base: Path) -> Path:
    """A new directory for one run in ``base``, named as ros2 launch names its own
    (``<date>-<time>-<microseconds>-<host>-<pid>``), with ``latest`` pointing to it."""
    from roc.handlers.logs import point_link

    while True:
        stamp = datetime.datetime.now().strftime("%Y-%m-%d-%H-%M-%S-%f")
        directory = base / f"{stamp}-{socket.gethostname()}-{os.getpid()}"
        try:
            directory.mkdir(parents=True)
            break
        except FileExistsError:
            continue
    point_link(base / "latest", str(directory))
    return directory


def file_name(process: str) -> str:
    """A process name as a file name (launch names such as ``talker-1`` stay as they are)."""
    return "".join(c if c.isalnum() or c in "-_.@" else "_" for c in process).lstrip(".") or "_"


class ProcessLogs:
    def __init__(self, directory: Path):
        self.directory = directory
        self._files: dict[str, TextIO] = {}

    def _file(self, process: str) -> TextIO:
        if process not in self._files:
            self._files[process] = open(self.directory / f"{file_name(process)}.log", "a", buffering=1,
                                        errors="replace")
        return self._files[process]

    def write(self, process: str, text: str) -> None:
        self._file(process).write(text)

    def note(self, process: str, text: str) -> None:
        self._file(process).write(f"[roc] {time.strftime('%Y-%m-%d %H:%M:%S')} {text}\n")

    def close(self) -> None:
        for handle in self._files.values():
            handle.close()
        self._files.clear()
