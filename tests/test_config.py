"""roc.toml and colcon's defaults files: defaults for options, profiles, per-package settings, errors."""

from __future__ import annotations

import json

import pytest
from build_helpers import roc


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
    env = {**__import__("build_helpers").ros_env(), "COLCON_HOME": str(home)}
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
                     env={**__import__("build_helpers").ros_env(), "COLCON_DEFAULTS_FILE": str(user_defaults)})
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
