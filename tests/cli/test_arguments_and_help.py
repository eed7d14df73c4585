"""The command line itself: version, help, -C, usage errors as one line pointing at the verb's help,
the closest name for a mistyped command or option, and every group's help listing its commands."""

from __future__ import annotations

import argparse
import contextlib
import io
import re
import subprocess
from pathlib import Path

import pytest
from helpers.build import BIN, copy_fixture, roc, ros_env
from helpers.fixture_workspaces import (
    run_roc,
)

from roc import __version__
from roc.cli.commands import COMMANDS, verbs


@pytest.mark.parametrize("arguments, message", [
    (["work", "build", "--symlink-instal"],
     "roc work build: error: unrecognized arguments: --symlink-instal; did you mean --symlink-install? "
     "(see 'roc work build --help')"),
    (["work", "list", "--packages-sel", "core"], "did you mean --packages-select?"),
    (["work", "build", "--mixin", "release"], "roc work build: error: roc does not support --mixin (colcon-mixin; "),
    (["work", "build", "--mixin-files", "x.mixin"], "roc does not support --mixin-files (colcon-mixin; "),
    (["work", "lst"], "(see 'roc work --help')"),
    (["work", "build", "--parallel-workers", "x"], "(see 'roc work build --help')"),
    (["work", "list", "--packages-above-depth"], "(see 'roc work list --help')"),
    (["nope"], "(see 'roc --help')"),
    (["w", "ls", "--packages-select-regex", "("], "invalid pattern '(': "),  # roc's own usage errors too
    (["w", "ls", "--packages-select-regex", "("], "(see 'roc work list --help')"),
    (["work", "build", "--parallel-workers", "-1"], "or more (see 'roc work build --help')"),
])
def test_usage_errors_are_one_roc_error_line_pointing_at_the_verbs_help(arguments, message, tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path / "ws")
    result = roc(*arguments, cwd=workspace)
    assert result.returncode == 2
    lines = result.stderr.splitlines()
    # argparse's errors name the command (as ros2's and colcon's do), roc's own say "roc: error:"
    assert len(lines) == 1 and re.match(r"roc( [a-z_-]+)*: error: ", lines[0]) and message in lines[0], result.stderr


def test_allow_abbrev_is_off_in_every_parser() -> None:
    from roc.cli.commands import build_parser

    parser = build_parser()
    assert not parser.allow_abbrev and all(not leaf.allow_abbrev for leaf in parser.leaves.values())


def test_every_verb_takes_debug_after_it_too() -> None:
    """The internal error's hint says "run with --debug": where a user adds it, after the command."""
    from roc.cli.commands import build_parser

    for path, leaf in build_parser().leaves.items():
        assert "--debug" in leaf._option_string_actions, path
        if path != ("launch",):  # whose -d/--debug is ros2 launch's (and turns on roc's too)
            assert leaf._option_string_actions["--debug"].help == argparse.SUPPRESS, path  # shown in roc --help


def cli(*args: str, env: dict[str, str], cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN / "roc"), *args], env=env, cwd=cwd, capture_output=True, text=True, timeout=60,
                          stdin=subprocess.DEVNULL)


@pytest.mark.parametrize("words, hint", [
    (["work", "buld"], "unknown command 'buld'; did you mean 'build'? (see 'roc work --help')"),
    (["wrk", "build"], "unknown command 'wrk'; did you mean 'work'? (see 'roc --help')"),
    (["work", "clean", "pakages"], "unknown command 'pakages'; did you mean 'packages'? (see 'roc work clean --help')"),
    (["topic", "xyzzy"], "unknown command 'xyzzy'; choose from list, info, type, find, echo, pub, hz, bw, delay "
                         "(see 'roc topic --help')"),
])
def test_a_mistyped_command_gets_the_closest_name(tmp_path: Path, words: list[str], hint: str) -> None:
    result = cli(*words, env=ros_env(), cwd=tmp_path)
    group = hint.rsplit("(see '", 1)[1].split(" --help")[0]  # the group's parser reports it, as argparse does
    assert (result.returncode, result.stdout, result.stderr) == (2, "", f"{group}: error: {hint}\n")


def _help_of(name: str, parent_help: str) -> str:
    """A command's help text in its parent's --help (on the next line when the name is long)."""
    lines = parent_help.splitlines()
    index = next(i for i, line in enumerate(lines) if line.split()[:1] == [name])
    return " ".join((lines[index] + " " + lines[index + 1] if len(lines[index].split()) == 1 else lines[index])
                    .split())


def _help(*words: str) -> str:
    """``roc WORDS --help``, in this process."""
    from roc.cli.main import main

    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit):
        main([*words, "--help"])
    return out.getvalue()


def test_every_group_s_help_lists_all_its_commands(monkeypatch) -> None:
    monkeypatch.setenv("COLUMNS", "1000")  # no wrapped lines
    groups = [path for path, _, module, _ in COMMANDS if module is None]
    assert ("interface",) in groups
    for group in groups:
        text = _help_of(group[-1], _help(*group[:-1]))
        assert text.endswith(": " + ", ".join(verbs(group))), text
    assert _help_of("interface", _help()).endswith(": list, packages, package, show, proto")


def test_dash_c_runs_in_another_directory(tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path / "selection")
    result = run_roc("-C", str(workspace), "work", "list", "-t", "-n", "--packages-up-to", "lib_a", cwd=tmp_path)
    assert (result.returncode, result.stdout.split(), result.stderr) == (0, ["core", "msgs", "lib_a"], "")
    missing = run_roc("-C", str(tmp_path / "missing"), "work", "list", cwd=tmp_path)
    assert missing.returncode == 1
    assert missing.stderr == f"roc: error: -C {tmp_path / 'missing'}: No such file or directory\n"


def test_version(tmp_path: Path) -> None:
    result = run_roc("--version", cwd=tmp_path)
    assert (result.returncode, result.stdout) == (0, f"roc {__version__}\n")


def test_help(tmp_path: Path) -> None:
    result = run_roc("--help", cwd=tmp_path)
    assert result.returncode == 0
    assert result.stdout.startswith("usage: roc ") and "work" in result.stdout and "completion" in result.stdout
    listing = run_roc("work", "list", "--help", cwd=tmp_path)
    assert listing.returncode == 0 and "--packages-up-to" in listing.stdout and "--topological-order" in listing.stdout


@pytest.mark.parametrize("argv, message", [
    (["nosuchcommand"], "roc: error: unknown command 'nosuchcommand'; choose from work, w, topic"),
    (["work", "list", "--bogus"], "roc work list: error: unrecognized arguments: --bogus"),
    (["work", "list", "-n", "-p"], "not allowed with argument"),
    (["work", "graph", "--format", "yaml"], "invalid choice: 'yaml'"),
    (["completion", "tcsh"], "invalid choice: 'tcsh'"),
])
def test_bad_arguments_are_one_line_and_exit_2(tmp_path: Path, argv: list[str], message: str) -> None:
    result = run_roc(*argv, cwd=tmp_path)
    assert result.returncode == 2
    assert len(result.stderr.splitlines()) == 1 and message in result.stderr
    assert "--help" in result.stderr  # says where to look


def test_group_without_command_prints_its_help(tmp_path: Path) -> None:
    result = run_roc("work", cwd=tmp_path)
    assert result.returncode == 2 and result.stderr.startswith("usage: roc work") and result.stdout == ""
