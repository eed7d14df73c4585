"""The default maintainer of a new package: git's user.name and user.email, else the login name."""

from __future__ import annotations

import getpass
import shutil
import subprocess


def _git_config(key: str) -> str:
    git = shutil.which("git")
    if git is None:
        return ""
    try:
        result = subprocess.run([git, "config", key], capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return ""
    return result.stdout.strip() if result.returncode == 0 else ""


def _login_name() -> str:
    try:
        return getpass.getuser()
    except (KeyError, OSError):  # no passwd entry and no LOGNAME/USER (e.g. some containers)
        return "maintainer"


def default_maintainer(name: str | None, email: str | None) -> tuple[str, str]:
    """Fill in what was not given, as ros2 pkg create does (``<login>@todo.todo`` without a git email)."""
    name = name or _git_config("user.name") or _login_name()
    email = email or _git_config("user.email") or f"{_login_name()}@todo.todo"
    return name, email
