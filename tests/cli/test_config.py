"""roc.toml and colcon's defaults files: defaults for options, profiles, per-package settings, errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from helpers.build import add_plain_package, copy_fixture, roc, ros_env


@pytest.fixture
def ws(tmp_path):
    for name in ("alpha", "beta"):
        (tmp_path / "src" / name).mkdir(parents=True)
        (tmp_path / "src" / name / "CMakeLists.txt").write_text(
            f"cmake_minimum_required(VERSION 3.8)\nproject({name} NONE)\n"
            + ("find_package(alpha)\n" if name == "beta" else ""))
    (tmp_path / "elsewhere" / "gamma").mkdir(parents=True)
    (tmp_path / "elsewhere" / "gamma" / "CMakeLists.txt").write_text("project(gamma NONE)\n")
    return tmp_path


def _config(ws, *args: str) -> dict:
    result = roc("work", "config", *args, "--format", "json", cwd=ws)
    assert result.returncode == 0, result.stderr
    return {row["option"]: row for row in json.loads(result.stdout)["options"]}


def test_roc_toml_sets_defaults_and_the_command_line_wins(ws):
    (ws / "roc.toml").write_text('[defaults]\nbase-paths = ["src"]\n[list]\ntopological-order = true\n'
                                 'names-only = true\n')
    assert roc("work", "list", cwd=ws).stdout.split() == ["alpha", "beta"]
    assert roc("work", "list", "--base-paths", "elsewhere", cwd=ws).stdout.split() == ["gamma"]
    options = _config(ws, "list")
    assert options["--topological-order"]["value"] is True
    assert options["--topological-order"]["source"].startswith("roc.toml [list]")
    assert options["--topological-order"]["source"].endswith("roc.toml:4)")
    assert options["--paths-only"]["source"] == "default"


def test_profiles(ws):
    (ws / "roc.toml").write_text('[build]\ncmake-args = ["-DMODE=debug"]\n'
                                 '[profile.release.build]\ncmake-args = ["-DMODE=release"]\n')
    assert _config(ws)["--cmake-args"]["value"] == ["-DMODE=debug"]
    assert _config(ws, "--profile", "release")["--cmake-args"]["value"] == ["-DMODE=release"]
    result = roc("work", "build", "--profile", "release", "--packages-select", "alpha", cwd=ws)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "-DMODE=release" in (ws / "log" / "latest_build" / "alpha" / "command.log").read_text()
    missing = roc("work", "build", "--profile", "fast", cwd=ws)
    assert missing.returncode == 2 and "no [profile.fast]" in missing.stderr and "release" in missing.stderr


def test_package_settings_and_colcon_meta(ws):
    (ws / "colcon.meta").write_text('{"names": {"alpha": {"cmake-args": ["-DFROM_META=1"]}}}')
    (ws / "roc.toml").write_text('[package.beta]\nskip = true\n')
    result = roc("work", "build", cwd=ws)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "-DFROM_META=1" in (ws / "log" / "latest_build" / "alpha" / "command.log").read_text()
    assert "beta" not in result.stdout


@pytest.mark.slow
def test_metas_and_user_metas(ws, tmp_path):
    home = tmp_path / "colcon-home"
    (home / "metadata").mkdir(parents=True)
    (home / "metadata" / "mine.meta").write_text('{"names": {"alpha": {"cmake-args": ["-DFROM_USER=1"]}}}')
    (ws / "extra.meta").write_text('{"names": {"beta": {"cmake-args": ["-DFROM_METAS=1"]}}}')
    env = {**ros_env(), "COLCON_HOME": str(home)}
    assert roc("work", "build", "--metas", "extra.meta", cwd=ws, env=env).returncode == 0
    logs = ws / "log" / "latest_build"
    assert "-DFROM_USER=1" in (logs / "alpha" / "command.log").read_text()
    assert "-DFROM_METAS=1" in (logs / "beta" / "command.log").read_text()
    assert roc("work", "build", "--ignore-user-meta", "--force", cwd=ws, env=env).returncode == 0
    assert "-DFROM_USER=1" not in (logs / "alpha" / "command.log").read_text()


def test_colcon_defaults_files(ws, tmp_path):
    user_defaults = tmp_path / "user-defaults.yaml"
    user_defaults.write_text("build:\n  parallel-workers: 3\n  symlink-install: true\n")
    (ws / "colcon_defaults.yaml").write_text("build:\n  parallel-workers: 5\n")
    env_result = roc("work", "config", "--format", "json", cwd=ws,
                     env={**ros_env(), "COLCON_DEFAULTS_FILE": str(user_defaults)})
    options = {row["option"]: row for row in json.loads(env_result.stdout)["options"]}
    assert options["--parallel-workers"]["value"] == 5  # the workspace's file wins over the user's
    assert options["--symlink-install"]["value"] is True
    (ws / "roc.toml").write_text("[build]\nparallel-workers = 7\n")
    assert _config(ws)["--parallel-workers"]["value"] == 7  # roc.toml wins over both


@pytest.mark.parametrize("verb, text, line, words", [
    ("build", "[build]\nparallel-workers = \"two\"\n", 2, ["'parallel-workers'", "whole number"]),
    ("list", "[list]\n\nbogus = 1\n", 3, ["'bogus'", "not an option"]),
    ("graph", "[biuld]\nx = 1\n", 1, ["'biuld'", "unknown table; did you mean 'build'?"]),
    ("build", "[build\n", "1:7", ["invalid TOML"]),
    ("build", "[package.alpha]\ncolour = \"red\"\n", 2, ["'colour'", "unknown package setting"]),
    ("build", "[build]\ncmake-args = \"-DX=1\"\n", 2, ["'cmake-args'", "list of strings"]),
])
def test_errors_name_file_line_and_key(ws, verb, text, line, words):
    (ws / "roc.toml").write_text(text)
    result = roc("work", verb, cwd=ws)
    assert result.returncode == 2
    assert result.stderr.startswith(f"roc: error: {ws}/roc.toml:{line}: ")
    assert all(word in result.stderr for word in words), result.stderr
    assert len(result.stderr.splitlines()) == 1
    assert not (ws / "build").exists()


def test_configured_base_paths_are_relative_to_roc_toml_from_a_subdirectory(tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path / "ws")
    (workspace / "roc.toml").write_text('[defaults]\nbase-paths = ["src"]\n')
    expected = roc("work", "list", cwd=workspace)
    assert expected.returncode == 0, expected.stderr
    for directory in (workspace / "src", workspace / "src" / "core"):
        result = roc("work", "list", cwd=directory)
        assert result.returncode == 0, result.stderr
        assert result.stdout == expected.stdout and "src/core" in result.stdout
    # the command line's --base-paths is still taken from the current directory, as in colcon
    here = roc("work", "list", "-n", "--base-paths", ".", cwd=workspace / "src" / "core")
    assert here.stdout.split() == ["core"]


def test_configured_directories_are_relative_to_roc_toml(tmp_path: Path, monkeypatch) -> None:
    from roc.cli.commands import build_parser
    from roc.config import apply_configuration, load_configuration

    (tmp_path / "roc.toml").write_text('[build]\nbuild-base = "out/build"\ninstall-base = "/abs/install"\n')
    (tmp_path / "sub").mkdir()
    monkeypatch.chdir(tmp_path / "sub")
    parser = build_parser(["work", "build"])
    leaf = parser.leaves[("work", "build")]
    apply_configuration(leaf, load_configuration(tmp_path, "build", None))
    args = leaf.parse_args([])
    assert args.build_base == str(tmp_path / "out" / "build") and args.install_base == "/abs/install"


@pytest.mark.parametrize("toml, message", [
    ('[package.cor]\ncmake-args = ["-DX=1"]\n',
     "roc.toml:1: '[package.cor]': no package named 'cor' in the workspace; did you mean core?"),
    ('[build]\n\n[ package."lib_c" ]\n', "roc.toml:3: '[package.lib_c]': no package named 'lib_c'"),
    ("[list]\nbase-paths = [\"src\"\n", "roc.toml:2:20: invalid TOML: Unclosed array (at the end of the file)"),
    ("[list]\nbase-paths = \n", "roc.toml:2:14: invalid TOML: Invalid value"),
    ("[list]\npackages-selct = [\"core\"]\n",
     "roc.toml:2: 'packages-selct': not an option of this verb; did you mean 'packages-select'? options: "),
    ("[package.core]\ncmake-arg = []\n", "'cmake-arg': unknown package setting; did you mean 'cmake-args'?"),
])
def test_roc_toml_mistakes_name_the_line_and_the_closest_name(toml: str, message: str, tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path / "ws")
    (workspace / "roc.toml").write_text(toml)
    result = roc("work", "list", cwd=workspace / "src")
    assert result.returncode == 2
    lines = [line for line in result.stderr.splitlines() if not line.startswith("roc: using workspace root")]
    assert len(lines) == 1 and message in lines[0], result.stderr


def test_colcon_meta_values_are_type_checked(tmp_path):
    add_plain_package(tmp_path, "alpha")
    (tmp_path / "colcon.meta").write_text('{"names": {"alpha": {"cmake-args": "-DX=1"}}}')
    result = roc("work", "build", cwd=tmp_path)
    assert result.returncode == 2 and "colcon.meta" in result.stderr and "list of strings" in result.stderr
