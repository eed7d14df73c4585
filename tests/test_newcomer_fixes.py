"""Tests for the fixes of issue 17 (what a newcomer trial found)."""

from __future__ import annotations

import io
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from build_helpers import copy_fixture, roc, ros_env

from roc.engine.events import TaskOutput, TaskQueued, TaskStarted, Tick


class FakeLive:
    def __init__(self) -> None:
        self.updates: list[str] = []

    def start(self) -> None:
        pass

    def stop(self) -> None:
        pass

    def update(self, renderable, refresh: bool = False) -> None:
        self.updates.append(str(renderable))


def test_status_line_redraws_only_on_change_and_at_most_four_times_a_second():
    from rich.console import Console

    from roc.handlers.status import StatusLine

    now = [100.0]
    live = FakeLive()
    status = StatusLine(console=Console(file=io.StringIO(), width=120), live=live, clock=lambda: now[0])
    status(TaskQueued("a"))
    status(TaskStarted("a"))  # within 0.25 s of the first draw: not drawn
    assert live.updates == ["[0s] [0/1 done] [0 running] "]
    for _ in range(100):  # a burst of output in the same instant: no redraw
        status(TaskOutput("a", data=b"compiling"))
    assert len(live.updates) == 1
    now[0] += 0.3
    status(Tick(""))
    assert live.updates[-1] == "[0s] [0/1 done] [1 running] a"
    now[0] += 0.3
    for _ in range(100):  # unchanged text: never redrawn, however long it goes on
        status(TaskOutput("a", data=b"no progress here"))
        now[0] += 0.001
    assert len(live.updates) == 2
    status(TaskOutput("a", data=b"[ 45%] Building"))
    assert live.updates[-1] == "[0s] [0/1 done] [1 running] a 45%"
    # 10 s of events every 10 ms, the text changing each second: one redraw per change
    for _ in range(1000):
        now[0] += 0.01
        status(Tick(""))
    assert len(live.updates) == 3 + 10


def test_paths_entries_that_are_not_directories_are_ignored(tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path / "ws")
    (workspace / "src" / "README.md").write_text("a file beside the packages\n")
    # what a shell makes of 'src/*' (and a path that does not exist at all)
    paths = sorted(str(p.relative_to(workspace)) for p in (workspace / "src").iterdir())
    result = roc("work", "list", "-n", "--paths", *paths, "src/missing", cwd=workspace)
    assert result.returncode == 0, result.stderr
    assert "core" in result.stdout.split() and len(result.stdout.split()) == 10


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


def _underlay(tmp_path: Path) -> Path:
    """An installed underlay with 'pyp' (as in build_small) and 'user', which needs pyp at run time."""
    prefix = tmp_path / "underlay"
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    for name in ("pyp", "user", "leaf"):
        (index / name).write_text("")
    (prefix / "share" / "user").mkdir()
    (prefix / "share" / "user" / "package.xml").write_text(
        '<package format="3"><name>user</name><version>1.0.0</version><description>d</description>'
        '<maintainer email="m@example.com">M</maintainer><license>MIT</license>'
        "<exec_depend>pyp</exec_depend></package>\n")
    return prefix


@pytest.mark.slow
def test_overriding_an_underlay_package_warns_unless_allowed(tmp_path: Path) -> None:
    workspace = copy_fixture("build_small", tmp_path / "ws")
    prefix = _underlay(tmp_path)
    env = ros_env(AMENT_PREFIX_PATH=f"{prefix}{os.pathsep}{sys.prefix}")
    warned = roc("work", "build", "--packages-select", "pyp", cwd=workspace, env=env)
    assert warned.returncode == 0, warned.stderr
    assert "roc: warning: some selected packages are already installed in an underlay workspace" in warned.stderr
    assert f"'pyp' is in: {prefix}" in warned.stderr
    assert "--allow-overriding pyp" in warned.stderr
    allowed = roc("work", "build", "--packages-select", "pyp", "--allow-overriding", "pyp", "nothere",
                  cwd=workspace, env=env)
    assert allowed.returncode == 0, allowed.stderr
    assert "underlay" not in allowed.stderr
    assert "--allow-overriding: ignoring unknown package 'nothere'" in allowed.stderr


def test_overriding_an_unused_underlay_package_does_not_warn(tmp_path: Path) -> None:
    from roc.workspace.underlay import overridden_packages

    prefix = _underlay(tmp_path)
    env = {"AMENT_PREFIX_PATH": str(prefix)}
    assert overridden_packages({"leaf"}, tmp_path / "install", [], env) == {}
    assert overridden_packages({"pyp", "leaf"}, tmp_path / "install", [], env) == {"pyp": [prefix]}
    # once this workspace builds 'user' too, nothing in the underlay uses the old pyp
    assert overridden_packages({"pyp", "user"}, tmp_path / "install", [], env) == {}
    # an underlay that is this workspace's own install base is not an underlay
    assert overridden_packages({"pyp"}, prefix, [], env) == {}


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


def test_create_refuses_a_missing_parent_unless_asked(tmp_path: Path) -> None:
    missing = tmp_path / "nonexistent" / "dir"
    refused = roc("work", "create", "pkg_a", "--destination-directory", str(missing), cwd=tmp_path)
    assert refused.returncode == 2
    assert refused.stderr.startswith(f"roc: error: --destination-directory {missing}: {missing.parent} does not "
                                     "exist; create it, or add --parents")
    assert not (tmp_path / "nonexistent").exists()
    made = roc("work", "create", "pkg_a", "--destination-directory", str(missing), "--parents", cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    assert (missing / "pkg_a" / "package.xml").is_file()
    # the destination itself may be new, as with mkdir
    assert roc("work", "create", "pkg_b", "--destination-directory", "new", cwd=tmp_path).returncode == 0


def test_create_refuses_a_name_the_workspace_already_has(tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path / "ws")
    before = sorted(p.relative_to(workspace) for p in workspace.rglob("*"))
    for destination in ("src", "src/new_group"):
        result = roc("work", "create", "core", "--build-type", "ament_python", "--destination-directory",
                     destination, cwd=workspace)
        assert result.returncode == 2
        assert result.stderr.startswith(f"roc: error: the workspace {workspace} already has a package named "
                                        f"'core' (in {workspace / 'src' / 'core'}); choose another name")
    assert sorted(p.relative_to(workspace) for p in workspace.rglob("*")) == before


def _plain_cmake(workspace: Path, name: str, depends: str = "") -> None:
    directory = workspace / "src" / name
    directory.mkdir(parents=True)
    (directory / "CMakeLists.txt").write_text(
        f"cmake_minimum_required(VERSION 3.8)\nproject({name} NONE)\n{depends}"
        f"file(WRITE ${{CMAKE_CURRENT_BINARY_DIR}}/{name}Config.cmake \"\")\n"
        f"install(FILES ${{CMAKE_CURRENT_BINARY_DIR}}/{name}Config.cmake DESTINATION share/{name}/cmake)\n")


def test_env_without_a_package_is_a_clear_usage_error(tmp_path: Path) -> None:
    result = roc("work", "env", cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr == "roc: error: roc work env needs a package: roc work env PKG_NAME [-- CMD...] " \
                            "(see 'roc work env --help')\n"


@pytest.mark.slow
def test_env_prints_only_what_the_build_environment_changes(tmp_path: Path) -> None:
    _plain_cmake(tmp_path, "alpha")
    _plain_cmake(tmp_path, "beta", "find_package(alpha REQUIRED)\n")
    env = ros_env(OLDPWD="/somewhere/else", ROC_TEST_UNRELATED="1")
    assert roc("work", "build", cwd=tmp_path, env=env).returncode == 0
    env["OLDPWD"] = "/another/place"  # differs from the saved build environment: still not printed
    printed = roc("work", "env", "beta", cwd=tmp_path, env=env)
    assert printed.returncode == 0, printed.stderr
    names = [line.split("=", 1)[0] for line in printed.stdout.splitlines()]
    assert names == ["export CMAKE_PREFIX_PATH"], printed.stdout
    assert str(tmp_path / "install" / "alpha") in printed.stdout
    everything = roc("work", "env", "beta", "--all", cwd=tmp_path, env=env)
    assert "export PATH=" in everything.stdout and "export ROC_TEST_UNRELATED=1" in everything.stdout
    assert "export OLDPWD=/somewhere/else" in everything.stdout  # --all: the saved environment, as built
    # eval-ing the short form in the current environment gives the build environment's values
    evaluated = subprocess.run(["bash", "-c", 'eval "$1" && echo "$CMAKE_PREFIX_PATH|$PATH"', "_", printed.stdout],
                               capture_output=True, text=True, env=env)
    assert evaluated.stdout.strip() == f"{str(tmp_path / 'install' / 'alpha')}|{env['PATH']}"


@pytest.mark.slow
def test_cache_export_says_what_it_left_out_and_why(tmp_path: Path) -> None:
    workspace = tmp_path / "ws"
    _plain_cmake(workspace, "alpha")
    _plain_cmake(workspace, "beta", "find_package(alpha REQUIRED)\n")
    _plain_cmake(workspace, "fixed")
    with (workspace / "src" / "fixed" / "CMakeLists.txt").open("a") as cmake:
        cmake.write('file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/where.txt "${CMAKE_INSTALL_PREFIX}")\n'
                    "install(FILES ${CMAKE_CURRENT_BINARY_DIR}/where.txt DESTINATION share/fixed)\n")
    _plain_cmake(workspace, "never_built")
    built = roc("work", "build", "--packages-skip", "never_built", cwd=workspace)
    assert built.returncode == 0, built.stdout + built.stderr
    with (workspace / "src" / "alpha" / "CMakeLists.txt").open("a") as cmake:
        cmake.write("# changed after the build\n")
    result = roc("work", "cache", "export", str(tmp_path / "cache"), cwd=workspace)
    assert result.returncode == 0, result.stderr
    assert result.stdout == f"exported 1 up-to-date package(s) to {tmp_path / 'cache'}\n"
    assert result.stderr.splitlines() == [
        f"  fixed: import can restore it only into {workspace} (share/fixed/where.txt holds that path)",
        "  not exported: alpha: not up to date (it changed since its last build; build it first)",
        "  not exported: beta: not up to date (it changed since its last build; build it first)",
        "  not exported: never_built: not built successfully yet",
    ]
    index = json.loads((tmp_path / "cache" / "index.json").read_text())
    assert sorted(index["packages"]) == ["fixed"]


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


def _installed_links(prefix: Path) -> list[str]:
    return sorted(str(p.relative_to(prefix)) for p in prefix.rglob("*") if p.is_symlink())


@pytest.mark.slow
def test_switching_symlink_install_on_and_off_on_an_existing_build_base(tmp_path: Path) -> None:
    workspace = copy_fixture("build_small", tmp_path / "ws")
    core = workspace / "src" / "core"
    (core / "core_py").mkdir()
    (core / "core_py" / "__init__.py").write_text("VALUE = 1\n")
    cmake = (core / "CMakeLists.txt").read_text().replace(
        "ament_package()", "find_package(ament_cmake_python REQUIRED)\nament_python_install_package(core_py)\n"
                           "ament_package()")
    (core / "CMakeLists.txt").write_text(cmake)
    build = ("work", "build", "--packages-select", "core", "pyp")
    first = roc(*build, cwd=workspace)
    assert first.returncode == 0, first.stdout + first.stderr
    install = workspace / "install"
    assert _installed_links(install) == []
    on = roc(*build, "--symlink-install", cwd=workspace)
    assert on.returncode == 0, on.stdout + on.stderr  # was: "existing path cannot be removed: Is a directory"
    header = install / "core" / "include" / "core" / "core.hpp"
    assert header.is_symlink() and header.resolve() == (core / "include" / "core" / "core.hpp").resolve()
    assert any("pyp" in link for link in _installed_links(install / "pyp"))
    off = roc(*build, cwd=workspace)
    assert off.returncode == 0, off.stdout + off.stderr
    assert "AMENT_CMAKE_SYMLINK_INSTALL:BOOL=OFF" in (workspace / "build" / "core" / "CMakeCache.txt").read_text()
    assert _installed_links(install) == [] and header.is_file()
    assert (core / "core_py" / "__init__.py").read_text() == "VALUE = 1\n"
    site = next((install / "core" / "lib").glob("python*/site-packages"))
    assert (site / "core_py" / "__init__.py").read_text() == "VALUE = 1\n"


REPO = Path(__file__).resolve().parents[1]


def test_the_manual_says_what_a_newcomer_needs_to_know() -> None:
    """(The examples of the manual and the README are run by tests/test_docs.py.)"""
    work = " ".join((REPO / "docs" / "commands" / "work.md").read_text().split())
    assert "the PyPI wheels of this repository's `.venv` have no rclcpp" in work
    assert "That file is roc's own JSON-lines event format, not colcon's" in work
    bench = (REPO / "bench" / "README.md").read_text()
    assert "/work/" not in bench and "/home/" not in bench
    for script in sorted((REPO / "bench").glob("*.py")):
        assert f"## {script.name}" in bench or f"`{script.name}`" in bench, script.name
    assert "## incremental_bench.py" in bench
