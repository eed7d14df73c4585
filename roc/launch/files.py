"""Finding a launch file (``PKG FILE`` in the package's share directory, or a path) and reading launch
arguments (``name:=value``), with ros2 launch's rules and roc's one-line errors that list what exists."""

from __future__ import annotations

import os
from pathlib import Path

from roc.errors import RocError, UsageError

# What counts as a launch file when listing a package's: launch_xml's and launch_yaml's extensions, and
# Python files named *launch.py (ros2launch's is_launch_file).
LAUNCH_SUFFIXES = ("launch.py", ".xml", ".yaml", ".yml")


def launch_files(share: Path) -> list[Path]:
    """The launch files below a share directory, by path relative to it."""
    found = []
    for directory, subdirectories, files in os.walk(share):
        subdirectories.sort()
        for name in sorted(files):
            relative = Path(directory, name).relative_to(share)
            if name.endswith(LAUNCH_SUFFIXES) and ("launch" in name or "launch" in relative.parts[:-1]):
                found.append(relative)
    return found


def find_in_package(package: str, file_name: str) -> Path:
    """The one file named ``file_name`` anywhere in ``package``'s share directory (as ros2 launch looks)."""
    from roc.ament_index import share_directory
    from roc.messages import did_you_mean

    share = share_directory(package)
    matches = sorted(Path(directory, file_name) for directory, _, files in os.walk(share) if file_name in files)
    if len(matches) > 1:
        raise RocError(f"file '{file_name}' is in the share directory of package '{package}' "
                         f"{len(matches)} times: {', '.join(map(str, matches))}; give the path of the one to launch")
    if not matches:
        available = [str(path) for path in launch_files(share)]
        hint = did_you_mean(file_name, [Path(name).name for name in available], count=1)
        listing = f"its launch files: {', '.join(available)}" if available else "it has no launch files"
        raise RocError(f"no file '{file_name}' in the share directory of package '{package}' ({share}); "
                         f"{hint + ' ' if hint else ''}({listing})")
    return matches[0]


def parse_arguments(words: list[str]) -> list[tuple[str, str]]:
    """``name:=value`` words as (name, value) pairs, the last of duplicates winning (ros2 launch's rules:
    ``name:=`` is no argument, ``a:=b:=c`` gives ``a`` the value ``b:=c``)."""
    parsed: dict[str, str] = {}
    for word in words:
        name, separator, value = word.partition(":=")
        if not separator or not name or (not value and word.count(":=") == 1):
            raise UsageError(f"launch argument '{word}': expected NAME:=VALUE")
        parsed[name] = value
    return list(parsed.items())


def require_launch_library() -> None:
    """One line saying how to get the launch library when this Python cannot import it."""
    import importlib.util
    import sys

    missing = [name for name in ("launch", "launch_ros") if importlib.util.find_spec(name) is None]
    if missing:
        raise RocError(f"the ROS 2 launch library ({', '.join(missing)}) is not installed for {sys.executable}: "
                       "source your ROS 2 installation (e.g. /opt/ros/jazzy/setup.bash) or install "
                       "ros-<distro>-launch-ros, then run roc launch again")


def one_line(message: str) -> str:
    """The launch library's multi-line errors (``Caught multiple exceptions when trying to load file of format
    [py]:`` then `` - Error: ...`` per parser) as one line, each cause once."""
    head, *rest = message.strip().splitlines() or [""]
    causes = list(dict.fromkeys(line.strip()[2:] for line in rest if line.strip().startswith("- ")))
    return f"{head.rstrip(':')}: {'; '.join(causes)}" if causes else " ".join(message.split())
