"""scripts/setup.sh changes the system only when asked: ROC_SETUP_TEST_TOOLS=1 installs the test-time
tools with apt-get, CI opts in, and the script's header says what the option does."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

from helpers.build import REPO

# what the set-up runs, without zsh, fish, tmux, ccache and sshd
TOOLS = ("bash", "dirname", "sha256sum", "cut", "cat", "flock", "grep", "env", "rm")


def _setup_without_shells(tmp_path: Path, **extra: str) -> tuple[subprocess.CompletedProcess, str]:
    """Run a copy of scripts/setup.sh all through (ROC_SETUP_FORCE=1) as root, on a PATH without zsh and
    fish, in a checkout whose venv's Python does nothing, with an apt-get that records its arguments;
    returns the run and what apt-get was asked."""
    checkout = tmp_path / "checkout"
    (checkout / "scripts").mkdir(parents=True)
    shutil.copy(REPO / "scripts" / "setup.sh", checkout / "scripts")
    fake = tmp_path / "bin"
    fake.mkdir()
    for tool in TOOLS:
        os.symlink(shutil.which(tool), fake / tool)
    calls = tmp_path / "apt-get.calls"
    scripts = {fake / "apt-get": f'echo "$*" >> {calls}', fake / "id": "echo 0"}
    scripts.update({checkout / ".venv" / "bin" / name: "exit 0" for name in ("python", "roc", "colcon")})
    for path, body in scripts.items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(f"#!/bin/sh\n{body}\n")
        path.chmod(0o755)
    env = {"PATH": str(fake), "HOME": str(tmp_path), "TMPDIR": str(tmp_path), "ROC_SETUP_FORCE": "1", **extra}
    run = subprocess.run(["bash", str(checkout / "scripts" / "setup.sh")], env=env, capture_output=True, text=True,
                         timeout=120)
    return run, calls.read_text() if calls.exists() else ""


def test_the_set_up_installs_no_system_package_unless_asked(tmp_path: Path) -> None:
    run, asked = _setup_without_shells(tmp_path)
    assert run.returncode == 0, run.stderr
    assert asked == ""
    assert "setup: zsh fish tmux ccache openssh-server not installed: their tests will be skipped (ROC_SETUP_TEST_TOOLS=1 installs them)" in run.stderr


def test_roc_setup_test_tools_installs_zsh_fish_tmux_and_ccache_and_says_so(tmp_path: Path) -> None:
    run, asked = _setup_without_shells(tmp_path, ROC_SETUP_TEST_TOOLS="1")
    assert run.returncode == 0, run.stderr
    assert "setup: ROC_SETUP_TEST_TOOLS=1: installing zsh fish tmux ccache openssh-server with apt-get" in run.stderr
    assert asked.splitlines() == ["update -qq", "install -y -qq zsh fish tmux ccache openssh-server"]


def test_ci_opts_in_and_the_set_up_says_what_the_option_does() -> None:
    assert "export ROC_SETUP_TEST_TOOLS=1" in (REPO / ".ci" / "run").read_text()
    header = (REPO / "scripts" / "setup.sh").read_text().split("set -euo pipefail")[0]
    assert "ROC_SETUP_TEST_TOOLS=1  also install zsh, fish, tmux, ccache and openssh-server" in header
