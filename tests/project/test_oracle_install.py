"""The ros2 CLI oracle's venv (tests/helpers/graph.py: install_oracle) is used only once its install has
finished: a venv left half-installed (an install stopped or failed halfway, which the installer itself
would take as done) is made again from nothing. The installer's commands are stood in for here."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from helpers import graph


@pytest.fixture
def oracle(tmp_path: Path, monkeypatch) -> dict:
    """A venv path and an installer of its own; ``calls`` the commands run, ``fail`` makes the installer fail."""
    state: dict = {"calls": [], "fail": False, "venv": tmp_path / "cache" / "ros2cli-venv"}
    (tmp_path / "shared" / "oracles").mkdir(parents=True)
    (tmp_path / "shared" / "oracles" / "install_ros2cli.sh").touch()
    monkeypatch.setattr(graph, "SHARED", tmp_path / "shared")
    monkeypatch.setattr(graph, "ORACLE_VENV", state["venv"])

    def run(command: list[str], **_) -> subprocess.CompletedProcess:
        state["calls"].append(command)
        venv = state["venv"]
        if command[1:3] == ["-m", "venv"]:
            (venv / "bin").mkdir(parents=True)
        elif command[0] == "bash":  # the installer: ros2 is there before it is all done
            (venv / "bin" / "ros2").touch()
            if state["fail"]:
                return subprocess.CompletedProcess(command, 1, "", "stopped halfway")
        return subprocess.CompletedProcess(command, 0, "", "")

    monkeypatch.setattr(graph.subprocess, "run", run)
    return state


def test_a_half_installed_oracle_is_made_again_and_a_finished_one_is_kept(oracle) -> None:
    venv = oracle["venv"]
    (venv / "bin").mkdir(parents=True)
    (venv / "bin" / "ros2").touch()  # what an install stopped halfway leaves
    (venv / "left_over").touch()
    assert graph.install_oracle() is None
    assert not (venv / "left_over").exists() and (venv / graph.INSTALLED.format(part="ros2cli")).exists()
    oracle["calls"].clear()
    assert graph.install_oracle() is None
    assert oracle["calls"] == []  # marked installed: nothing runs


def test_an_install_that_fails_is_not_taken_as_done(oracle) -> None:
    oracle["fail"] = True
    assert graph.install_oracle() == "install_ros2cli.sh failed: stopped halfway"
    assert not (oracle["venv"] / graph.INSTALLED.format(part="ros2cli")).exists()
    oracle["fail"] = False
    oracle["calls"].clear()
    assert graph.install_oracle() is None
    assert [call[0] for call in oracle["calls"]][1] == "bash"  # the installer ran again
