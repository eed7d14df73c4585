"""Package selection, ordering and recursive dependencies on packages built in code (no discovery)."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest
from helpers.build import copy_fixture, roc

from roc.cli.options import add_selection_arguments
from roc.errors import UsageError
from roc.workspace.dependencies import (
    DependencyCycleError,
    recursive_dependencies,
    topological_order,
)
from roc.workspace.package import Package
from roc.workspace.selection import (
    check_selection_arguments,
    ignore_packages,
    select_packages,
)


def package(name: str, build: tuple[str, ...] = (), run: tuple[str, ...] = (), test: tuple[str, ...] = ()) -> Package:
    return Package(name=name, path=Path("src", name), type="ros.ament_cmake",
                   dependencies={"build": {"ament_cmake", *build}, "run": set(run), "test": set(test)})


def workspace() -> list[Package]:
    """The graph of workspaces/fixtures/selection (``depend`` is build and run)."""
    return [
        package("core"), package("extra"), package("msgs"), package("standalone"),
        package("util", build=("core", "extra")),
        package("lib_a", build=("core", "msgs"), run=("core", "msgs")),
        package("lib_b", run=("util",), test=("test_helper",)),
        package("test_helper", run=("core",)),
        package("app", build=("lib_a", "lib_b"), run=("lib_a",)),
        package("tool", run=("msgs",), test=("app",)),
    ]


ORDER = ["core", "extra", "msgs", "standalone", "lib_a", "test_helper", "util", "lib_b", "app", "tool"]


def parse(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    add_selection_arguments(parser)
    return parser.parse_args(argv)


def selected(*argv: str, packages: list[Package] | None = None, build_base: Path | None = None) -> list[str]:
    """The selected names in topological order, after the same checks roc's commands make."""
    args = parse(*argv)
    packages = packages if packages is not None else workspace()
    check_selection_arguments(args, {p.name for p in packages})
    ordered = topological_order(ignore_packages(args, packages))
    chosen = select_packages(args, ordered, build_base)
    return [p.name for p in ordered if p.name in chosen]


def test_topological_order_is_layered_and_alphabetical() -> None:
    assert [p.name for p in topological_order(workspace())] == ORDER
    assert [p.name for p in topological_order(reversed(workspace()))] == ORDER


def test_recursive_dependencies_follow_every_category_with_depths() -> None:
    by_name = {p.name: p for p in workspace()}
    # lib_b -test-> test_helper -run-> core; lib_b -run-> util -build-> core, extra
    assert recursive_dependencies(by_name["lib_b"], by_name) == {"util": 1, "test_helper": 1, "core": 2, "extra": 2}
    # tool -test-> app: the test dependency's whole tree is included
    assert set(recursive_dependencies(by_name["tool"], by_name)) == set(ORDER) - {"standalone", "tool"}
    # colcon's restore_build_isolation behaviour: only run dependencies beyond the direct ones
    assert recursive_dependencies(by_name["lib_b"], by_name, ("run",)) == {"util": 1, "test_helper": 1, "core": 2}
    assert recursive_dependencies(by_name["core"], by_name) == {}


def test_a_dependency_on_itself_is_ignored() -> None:
    packages = [package("a", build=("a",)), package("b", build=("a",))]
    assert [p.name for p in topological_order(packages)] == ["a", "b"]
    by_name = {p.name: p for p in packages}
    assert recursive_dependencies(by_name["a"], by_name) == {}


def test_cycle_error_shows_the_chain() -> None:
    packages = [package("a", build=("b",)), package("b", run=("c",)), package("c", test=("a",)),
                package("d", build=("a",))]
    with pytest.raises(DependencyCycleError) as error:
        topological_order(packages)
    message = str(error.value)
    assert message.startswith("dependency cycle: ")
    chain = message.removeprefix("dependency cycle: ").split(";")[0]
    # The chain may start anywhere on the cycle; it follows "depends on" edges and closes on itself.
    steps = re.findall(r"(\w+) -\[([\w,]+)\]-> (?=(\w+))", chain)
    assert sorted(steps) == [("a", "build", "b"), ("b", "run", "c"), ("c", "test", "a")]
    assert chain.split(" ")[0] == chain.split(" ")[-1]
    assert "a (src/a)" in message and "d (" not in message
    assert message.endswith("Remove one of these dependencies to break the cycle.")


@pytest.mark.parametrize("argv, expected", [
    ((), ORDER),
    (("--packages-up-to", "app"), ["core", "extra", "msgs", "lib_a", "test_helper", "util", "lib_b", "app"]),
    (("--packages-up-to", "lib_a", "test_helper"), ["core", "msgs", "lib_a", "test_helper"]),
    (("--packages-up-to-regex", "lib_."), ["core", "extra", "msgs", "lib_a", "test_helper", "util", "lib_b"]),
    # both: each narrows the selection on its own
    (("--packages-up-to", "app", "--packages-up-to-regex", "test.*"), ["core", "test_helper"]),
    (("--packages-above", "util"), ["util", "lib_b", "app", "tool"]),
    (("--packages-above-and-dependencies", "util"),
     ["core", "extra", "msgs", "lib_a", "test_helper", "util", "lib_b", "app", "tool"]),
    (("--packages-above-depth", "1", "core"), ["core", "lib_a", "test_helper", "util"]),
    (("--packages-above-depth", "0", "core"), ["core"]),
    (("--packages-above-depth", "2", "core"), ["core", "lib_a", "test_helper", "util", "lib_b", "app"]),
    (("--packages-select-by-dep", "util"), ["lib_b", "app", "tool"]),
    (("--packages-skip-by-dep", "core"), ["core", "extra", "msgs", "standalone"]),
    (("--packages-skip-up-to", "lib_b"), ["msgs", "standalone", "lib_a", "app", "tool"]),
    (("--packages-select", "app", "core"), ["core", "app"]),
    (("--packages-select",), []),
    (("--packages-skip", "app", "core"),
     ["extra", "msgs", "standalone", "lib_a", "test_helper", "util", "lib_b", "tool"]),
    (("--packages-select-regex", "lib", "t.*l$"), ["lib_a", "lib_b", "tool"]),  # re.match: not 'util'
    (("--packages-skip-regex", ".*_"), ["core", "extra", "msgs", "standalone", "util", "app", "tool"]),
    (("--packages-start", "lib_a", "--packages-end", "lib_b"), ["lib_a", "test_helper", "util", "lib_b"]),
    (("--packages-start", "app"), ["app", "tool"]),
    (("--packages-end", "extra"), ["core", "extra"]),
    (("--packages-select", "app", "--packages-up-to", "lib_a"), []),
    (("--packages-up-to", "app", "--packages-skip", "lib_a"),
     ["core", "extra", "msgs", "test_helper", "util", "lib_b", "app"]),
])
def test_selection(argv: tuple[str, ...], expected: list[str]) -> None:
    assert selected(*argv) == expected


def test_ignore_removes_packages_from_the_graph() -> None:
    # util ignored: lib_b no longer reaches core and extra through it
    assert selected("--packages-ignore", "util", "--packages-up-to", "lib_b") == ["core", "test_helper", "lib_b"]
    # app ignored: tool's test dependency on it is gone, so tool moves up to the second layer
    assert selected("--packages-ignore-regex", ".*a.*") == ["core", "msgs", "test_helper", "tool", "util", "lib_b"]


def test_skipped_packages_stay_in_the_graph() -> None:
    # util skipped, not ignored: lib_b's recursive dependencies still go through it
    assert selected("--packages-skip", "util", "--packages-up-to", "lib_b") == ["core", "extra", "test_helper", "lib_b"]


@pytest.mark.parametrize("argv, message", [
    (("--packages-up-to", "ap"), "--packages-up-to: no package named 'ap' in the workspace; did you mean app?"),
    (("--packages-above", "nothing_like_it"), "run 'roc work list -n' to see the package names"),
    (("--packages-above-depth", "1", "x"), "--packages-above-depth: no package named 'x'"),
    (("--packages-above-depth", "one", "core"), "the first value must be a depth"),
    (("--packages-start", "x"), "--packages-start: no package named 'x'"),
    (("--packages-end", "x"), "--packages-end: no package named 'x'"),
    (("--packages-up-to-regex", "zzz"), "--packages-up-to-regex 'zzz' matches no package name"),
    (("--packages-skip-regex", "[a-"), "--packages-skip-regex: invalid pattern '[a-'"),
    (("--packages-start", "tool", "--packages-end", "core"),
     "--packages-end 'core' comes before --packages-start 'tool'"),
])
def test_usage_errors(argv: tuple[str, ...], message: str) -> None:
    with pytest.raises(UsageError) as error:
        selected(*argv)
    assert message in str(error.value)
    assert error.value.exit_code == 2


# What colcon does with a name the workspace lacks, option by option: warn and go on, go on, or stop.
COLCON_WARNS = ("--packages-select", "--packages-skip", "--packages-ignore")
COLCON_SAYS_NOTHING = ("--packages-select-by-dep", "--packages-skip-by-dep", "--packages-skip-up-to")
COLCON_REFUSES = ("--packages-up-to", "--packages-above", "--packages-above-and-dependencies")


def test_an_unknown_name_in_a_name_list_is_ignored_with_a_warning(capsys: pytest.CaptureFixture[str]) -> None:
    assert selected("--packages-skip", "not_here", "cor", "util") == [n for n in ORDER if n != "util"]
    assert capsys.readouterr().err == ("roc: warning: ignoring unknown package 'not_here' in --packages-skip\n"
                                       "roc: warning: ignoring unknown package 'cor' in --packages-skip; "
                                       "did you mean 'core'?\n")
    assert selected("--packages-select", "not_here", "app") == ["app"]
    assert selected("--packages-select-by-dep", "not_here") == []
    assert selected("--packages-ignore", "not_here", "--packages-skip-up-to", "not_here", "lib_a") == [
        "extra", "standalone", "test_helper", "util", "lib_b", "app", "tool"]


@pytest.mark.slow  # runs the real colcon
def test_unknown_names_are_ignored_or_refused_option_by_option_as_colcon_does(tmp_path: Path) -> None:
    """So that a command line shared between repositories (--packages-skip of a package only some have) keeps
    working: where colcon goes on (with a warning, or without one) roc goes on with a warning; where an
    unknown name leaves the selection without meaning (where it starts or ends), both stop."""
    import subprocess

    from helpers.build import BIN, ros_env

    workspace = copy_fixture("selection", tmp_path / "ws")
    known = {"--packages-select": "app lib_a util tool", "--packages-skip": "tool", "--packages-ignore": "standalone",
             "--packages-select-by-dep": "core", "--packages-skip-by-dep": "extra", "--packages-skip-up-to": "msgs"}
    going_on = [word for option in COLCON_WARNS + COLCON_SAYS_NOTHING
                for word in (option, f"no_{option[11:]}", *known[option].split())]
    refused = [word for option in COLCON_REFUSES for word in (option, "not_here")]
    runs = {"going on": going_on, "refused": refused, "start": ["--packages-start", "not_here"],
            "end": ["--packages-end", "not_here"]}
    # colcon takes about a second to start: all at once
    colcons = {run: subprocess.Popen([str(BIN / "colcon"), "list", "-n", *words], cwd=workspace, env=ros_env(),
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
               for run, words in runs.items()}
    outputs = {run: (*process.communicate(timeout=120), process.returncode) for run, process in colcons.items()}
    ours = {run: roc("work", "list", "-n", *words, cwd=workspace) for run, words in runs.items()}

    out, err, code = outputs["going on"]
    assert (code, ours["going on"].returncode) == (0, 0) and out.split() and ours["going on"].stdout == out
    for option in COLCON_WARNS + COLCON_SAYS_NOTHING:
        warning = f"ignoring unknown package 'no_{option[11:]}' in {option}"
        assert (warning in err) == (option in COLCON_WARNS), (option, err)
        assert f"roc: warning: {warning}\n" in ours["going on"].stderr
    out, err, code = outputs["refused"]
    assert code != 0 and err.splitlines() == [f"Package 'not_here' specified with {option} was not found"
                                              for option in COLCON_REFUSES]
    assert ours["refused"].returncode == 2 and ours["refused"].stderr.startswith(
        f"roc: error: {COLCON_REFUSES[0]}: no package named 'not_here' in the workspace")
    for run in ("start", "end"):
        assert outputs[run][2] != 0 and outputs[run][1].strip() == f"Package 'not_here' specified with --packages-{run} was not found"
        assert ours[run].returncode == 2 and f"--packages-{run}: no package named 'not_here'" in ours[run].stderr


def test_a_package_named_as_the_verbs_argument_must_exist(tmp_path: Path) -> None:
    """``roc work test PKG`` is short for --packages-select PKG, but a name typed there is meant: an error."""
    workspace = copy_fixture("selection", tmp_path / "ws")
    result = roc("work", "test", "ap", cwd=workspace)
    assert result.returncode == 2
    assert result.stderr.startswith("roc: error: no package named 'ap' in the workspace; did you mean app?")


def test_pattern_that_matches_nothing_warns(capsys: pytest.CaptureFixture[str]) -> None:
    assert selected("--packages-select-regex", "zzz") == []
    assert "roc: warning: --packages-select-regex 'zzz' matches no package name" in capsys.readouterr().err


def test_previous_build_results(tmp_path: Path) -> None:
    for name, result in {"core": "0", "util": "1", "lib_a": "SIGINT"}.items():
        (tmp_path / name).mkdir()
        (tmp_path / name / "colcon_build.rc").write_text(f"{result}\n")
    assert selected("--packages-select-build-failed", build_base=tmp_path) == ["util"]
    # not finished: failed, interrupted and never built
    assert selected("--packages-skip-build-finished", build_base=tmp_path) == [n for n in ORDER if n != "core"]


def test_paths_entries_that_are_not_directories_are_ignored(tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path / "ws")
    (workspace / "src" / "README.md").write_text("a file beside the packages\n")
    # what a shell makes of 'src/*' (and a path that does not exist at all)
    paths = sorted(str(p.relative_to(workspace)) for p in (workspace / "src").iterdir())
    result = roc("work", "list", "-n", "--paths", *paths, "src/missing", cwd=workspace)
    assert result.returncode == 0, result.stderr
    assert "core" in result.stdout.split() and len(result.stdout.split()) == 10
