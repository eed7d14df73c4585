"""What the distribution suite's own tests share: the other distribution's venv (the tests of what one
distribution made, used on the other, run in the Kilted suite, which CI runs after Jazzy's: both venvs are
there) and the environment of a process of either distribution."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from helpers.build import DISTRO, REPO
from helpers.graph import graph_env
from helpers.oracles import require_oracle

DISTROS = ("jazzy", "kilted")
OTHER = next(name for name in DISTROS if name != DISTRO)


def venv(distro: str) -> Path:
    """The venv scripts/setup.sh makes for ``distro``."""
    return REPO / (".venv" if distro == "jazzy" else f".venv-{distro}")


def require_both() -> None:
    """Run only in the Kilted suite (CI has set up both venvs by then), with the other venv there."""
    if DISTRO == "jazzy":
        pytest.skip("runs in the Kilted suite (bash scripts/test.sh --distro kilted), after both set-ups")
    require_oracle(f"ROS 2 {OTHER}'s venv (bash scripts/setup.sh --distro {OTHER})", venv(OTHER) / "bin" / "roc")


def env_of(distro: str, slot: int, runtime: Path, **extra: str) -> dict[str, str]:
    """graph_env for a process of ``distro``: its venv as the only ROS 2 and first on PATH."""
    bin_dir = venv(distro) / "bin"
    env = graph_env(slot, runtime, AMENT_PREFIX_PATH=str(venv(distro)), **extra)
    env["PATH"] = os.pathsep.join([str(bin_dir), *(p for p in env["PATH"].split(os.pathsep)
                                                   if not p.startswith(str(REPO / ".venv")))])
    # the library path the wheels' bootstrapper gave this (test) process is its own venv's: without it and
    # its done-flag, a process of the other venv sets its own
    for name in ("VIRTUAL_ENV", "LD_LIBRARY_PATH", "_ROS_WHEELS_BOOTSTRAP_COMPLETE"):
        env.pop(name, None)
    return env
