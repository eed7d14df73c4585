"""Shell completion of commands, options and workspace package names in bash, zsh and fish (graph names
from a running daemon: tests/graph/test_daemon_lifetime_and_completion.py)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.build import copy_fixture, roc, ros_env
from helpers.fixture_workspaces import (
    run_roc,
    tool_environment,
)


def _completion_script(shell: str, directory: Path) -> Path:
    result = roc("completion", shell, cwd=directory)
    assert result.returncode == 0, result.stderr
    path = directory / f"roc.{shell}"
    path.write_text(result.stdout)
    return path


BASH_COMPLETIONS = [  # words after 'roc', the word completed last -> COMPREPLY
    (["work", "build", "lib_"], "lib_a lib_b"),
    (["work", "b", "core", "lib_"], "lib_a lib_b"),
    (["work", "info", "t"], "test_helper tool"),
    (["work", "env", "ap"], "app"),
    (["work", "build", "--packages-select", "core", "lib_"], "lib_a lib_b"),  # every value of a list option
    (["work", "list", "--packages-skip", "app", "--packages-ignore", "s"], "standalone"),
    (["work", "build", "--packages-start", "core", "a"], "app"),  # after a one-value option: positional
    (["work", "build", "--executor", "s"], "sequential"),
    (["work", "build", "--event-handlers", "summary-", "status"], "status+ status-"),
    (["work", "list", "--format", ""], "text json"),
    (["work", "cache", "ex"], "export"),
    (["work", "build", "--symlink-install", "--packages-up-to", "msg"], "msgs"),
    (["work", "build", "--packages-select-reg"], "--packages-select-regex"),
    (["work", "build", "--packages-select-regex", "li"], ""),  # a pattern: nothing to offer
    (["completion", "f"], "fish"),
]


@pytest.mark.slow
def test_bash_completes_positional_package_names_and_every_list_value(tmp_path: Path) -> None:
    script = _completion_script("bash", tmp_path)
    workspace = copy_fixture("selection", tmp_path / "ws")
    probe = [f"source {script}"]
    for words, _ in BASH_COMPLETIONS:
        quoted = " ".join(f"'{w}'" for w in ["roc", *words])
        probe.append(f'COMP_WORDS=({quoted}); COMP_CWORD={len(words)}; _roc_complete; echo "${{COMPREPLY[*]}}"')
    result = subprocess.run(["bash", "-c", "\n".join(probe)], cwd=workspace, env=ros_env(), capture_output=True,
                            text=True, timeout=120)
    assert result.stdout.splitlines() == [expected for _, expected in BASH_COMPLETIONS], result.stderr


@pytest.mark.slow
def test_zsh_completes_with_the_bash_function(tmp_path: Path) -> None:
    if shutil.which("zsh") is None:
        pytest.skip("zsh is not installed (ROC_SETUP_TEST_TOOLS=1 bash scripts/setup.sh installs it)")
    script = _completion_script("zsh", tmp_path)
    assert subprocess.run(["zsh", "-n", str(script)], capture_output=True).returncode == 0
    workspace = copy_fixture("selection", tmp_path / "ws")
    # zsh's compgen emulation leaves filtering by the typed prefix to zsh's completion system (which this
    # probe does not run), so each probe shows which kind of value was offered
    probe = [f"source {script}", "setopt ksharrays"]  # as bashcompinit's _bash_complete does
    for words in (["work", "build", "--packages-select", "core", "lib_"], ["work", "build", "--executor", "s"],
                  ["work", "info", "x"]):
        probe.append(f"COMP_WORDS=(roc {' '.join(words)}); COMP_CWORD={len(words)}; _roc_complete; "
                     'echo "${COMPREPLY[*]}"')
    result = subprocess.run(["zsh", "-f", "-c", "\n".join(probe)], cwd=workspace,
                            env={**ros_env(), "HOME": str(tmp_path)}, capture_output=True, text=True, timeout=120)
    packages = "app core extra lib_a lib_b msgs standalone test_helper tool util"
    assert result.stdout.splitlines() == [packages, "parallel sequential", packages], result.stdout + result.stderr


@pytest.mark.slow
@pytest.mark.parametrize("line, expected", [
    ("roc work build lib_", ["lib_a", "lib_b"]),
    ("roc work info core t", ["test_helper", "tool"]),
    ("roc work build --packages-select core lib_", ["lib_a", "lib_b"]),
    ("roc work build --executor s", ["sequential"]),
    ("roc work build --packages-start core a", ["app"]),
    ("roc work env ap", ["app"]),
])
def test_fish_completes_positional_package_names_and_every_list_value(line: str, expected: list[str],
                                                                       tmp_path: Path) -> None:
    if shutil.which("fish") is None:
        pytest.skip("fish is not installed (ROC_SETUP_TEST_TOOLS=1 bash scripts/setup.sh installs it)")
    script = _completion_script("fish", tmp_path)
    assert subprocess.run(["fish", "-n", str(script)], capture_output=True).returncode == 0
    workspace = copy_fixture("selection", tmp_path / "ws")
    probe = f"source {script}; complete -C '{line}'"
    result = subprocess.run(["fish", "--no-config", "-c", probe], cwd=workspace,
                            env={**ros_env(), "HOME": str(tmp_path)}, capture_output=True, text=True, timeout=120)
    assert [row.split("\t")[0] for row in result.stdout.splitlines()] == expected, result.stderr


def completion_script(shell: str, tmp_path: Path) -> Path:
    result = run_roc("completion", shell, cwd=tmp_path)
    assert result.returncode == 0 and result.stderr == ""
    path = tmp_path / f"roc.{shell}"
    path.write_text(result.stdout)
    return path


def test_bash_completion_parses_and_completes(tmp_path: Path) -> None:
    script = completion_script("bash", tmp_path)
    assert subprocess.run(["bash", "-n", str(script)], capture_output=True).returncode == 0
    workspace = copy_fixture("selection", tmp_path / "selection")
    # roc must be on PATH for package names: the directory of this interpreter holds the roc script
    env = {**tool_environment(), "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    probe = (f"source {script}\n"
             "COMP_WORDS=(roc w li); COMP_CWORD=2; _roc_complete; echo \"${COMPREPLY[*]}\"\n"
             "COMP_WORDS=(roc work list --packages-up); COMP_CWORD=3; _roc_complete; echo \"${COMPREPLY[*]}\"\n"
             "COMP_WORDS=(roc work list --packages-up-to li); COMP_CWORD=4; _roc_complete; echo \"${COMPREPLY[*]}\"\n")
    result = subprocess.run(["bash", "-c", probe], cwd=workspace, env=env, capture_output=True, text=True, timeout=60)
    expected = ["list", "--packages-up-to --packages-up-to-regex", "lib_a lib_b"]
    assert result.stdout.splitlines() == expected, result.stderr


@pytest.mark.parametrize("shell", ["zsh", "fish"])
def test_other_shells_parse(shell: str, tmp_path: Path) -> None:
    script = completion_script(shell, tmp_path)
    assert script.read_text().startswith(f"# roc {shell} completion")
    if shutil.which(shell) is None:
        pytest.skip(f"{shell} is not installed")
    result = subprocess.run([shell, "-n", str(script)], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
