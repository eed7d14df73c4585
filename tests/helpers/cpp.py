"""The C++ stack that ``bash scripts/setup.sh --with-cpp`` builds with roc (rclcpp, rclcpp_components, the
demos' and examples' C++ nodes, in .cpp-stack/): whether it is there, and the environment of a shell that
sourced it. Tests marked ``cpp`` need it: without it they are skipped with the reason ``the C++ stack is
not built: ...`` (conftest.py sums these up), except in CI, which builds it: there they fail."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

from helpers.oracles import REPO, skip_or_fail

STACK = REPO / ".cpp-stack"
INSTALL = STACK / "stack" / "install"
SETUP_COMMAND = "bash scripts/setup.sh --with-cpp"
MISSING = f"the C++ stack is not built: run {SETUP_COMMAND}"


def require_stack() -> Path:
    """The stack's install base; skips the test (fails it in CI) when the stack is not built."""
    if not (STACK / "ready").is_file():
        skip_or_fail(MISSING, "CI builds it before the tests")
    return INSTALL


def sourced(env: dict[str, str], setup: Path | None = None) -> dict[str, str]:
    """``env`` after ``source`` of the stack's (or ``setup``'s) setup.bash in bash, as a user's shell."""
    script = setup or require_stack() / "setup.bash"
    result = subprocess.run(["bash", "-c", 'source "$1" && env -0', "_", str(script)], env=env,
                            capture_output=True, check=True)
    return dict(item.split("=", 1) for item in result.stdout.decode().split("\0") if "=" in item)


def library_path(env: dict[str, str]) -> list[str]:
    return [entry for entry in env.get("LD_LIBRARY_PATH", "").split(os.pathsep) if entry]
