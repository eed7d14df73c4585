"""The manual (docs/, MkDocs): it builds with warnings as errors, its CLI reference covers every option of
roc's argument parser, and the runnable examples of its pages (and of README.md) print what the pages
show (the convention: tests/helpers/docs_examples.py)."""

from __future__ import annotations

import importlib.util
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.docs_examples import (
    REPO,
    Sequence,
    matches,
    pages,
    reader_environment,
    sequences,
    split_at_interrupt,
    unchecked_output_blocks,
)

from roc.cli.commands import build_parser

BIN = Path(sys.executable).parent
README_MAX_LINES = 250


def _mkdocs_build(root: Path, site: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    return subprocess.run([str(BIN / "mkdocs"), "build", "--strict", "--site-dir", str(site)], cwd=root,
                          env=env, capture_output=True, text=True, timeout=300)


@pytest.mark.slow  # a few seconds (the quick loop stays under 45 s)
def test_the_manual_builds_with_warnings_as_errors(tmp_path: Path) -> None:
    result = _mkdocs_build(REPO, tmp_path / "site")
    assert result.returncode == 0, result.stdout + result.stderr
    for page in ("index.html", "commands/topic/index.html", "reference/work/index.html", "reference/idl/index.html"):
        assert (tmp_path / "site" / page).is_file(), page
    echo = (tmp_path / "site" / "reference" / "topic" / "index.html").read_text()
    assert 'id="roc-topic-echo--csv"' in echo
    assert not (tmp_path / "site" / "hooks").exists()


@pytest.mark.slow  # a few seconds (the quick loop stays under 45 s)
def test_a_broken_link_or_a_page_outside_the_nav_fails_the_build(tmp_path: Path) -> None:
    shutil.copytree(REPO / "docs", tmp_path / "docs")
    shutil.copy(REPO / "mkdocs.yml", tmp_path)
    (tmp_path / "roc").symlink_to(REPO / "roc")  # mkdocs.yml watches it
    (tmp_path / "docs" / "commands" / "stray.md").write_text("# Stray\n")
    topic = tmp_path / "docs" / "commands" / "topic.md"
    topic.write_text(topic.read_text() + "\n[gone](../nowhere.md) [no anchor](../reference/topic.md#roc-topic-nope)\n")
    result = _mkdocs_build(tmp_path, tmp_path / "site")
    assert result.returncode != 0
    log = result.stdout + result.stderr
    assert "commands/stray.md" in log and "nowhere.md" in log and "roc-topic-nope" in log, log


def _reference_hook():
    spec = importlib.util.spec_from_file_location("cli_reference", REPO / "docs" / "hooks" / "cli_reference.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def test_the_reference_has_every_verb_and_option_with_its_help() -> None:
    hook = _reference_hook()
    reference = hook.reference_pages(existing=set())
    assert "(no help text)" not in "".join(reference.values())
    for path, leaf in build_parser().leaves.items():
        page = reference[f"reference/{path[0]}.md"]
        anchor = "-".join(("roc", *path))
        assert f"{{ #{anchor} }}" in page, anchor
        for action in leaf._actions:
            if action.help in (None, "==SUPPRESS==") or "-h" in action.option_strings:
                continue
            if action.option_strings:  # in the verb's own section, or in a shared group's
                option = max(action.option_strings, key=len)
                assert re.search(rf"{{ #[\w-]*{re.escape(option)} }}", page), f"{anchor} {option}"
            help_text = action.help % {**vars(action), "prog": leaf.prog}
            assert hook.text(help_text) in page, f"{anchor}: {help_text}"


def test_hand_written_pages_have_no_option_tables() -> None:
    """Options are described once, in the generated reference; the guides link to it."""
    for page in pages():
        for number, line in enumerate(page.read_text().splitlines(), 1):
            assert not re.match(r"\|\s*(option|options|flag)\s*\|", line.lower()), f"{page}:{number}: {line}"


def test_readme_is_a_landing_page() -> None:
    readme = (REPO / "README.md").read_text()
    assert len(readme.splitlines()) <= README_MAX_LINES
    for target in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", readme):
        if "://" not in target:
            assert (REPO / target).exists(), target


# ---- the runnable examples ----------------------------------------------------------------------

def test_expected_output_matching() -> None:
    assert matches(["a", "...", "d"], ["a", "b", "c", "d"])
    assert matches(["a", "...", "b"], ["a", "b"])
    assert matches(["Finished <<< x [...]"], ["Finished <<< x [0.81s]  "])
    assert not matches(["Finished <<< x [...]"], ["Finished <<< y [0.81s]"])
    assert not matches(["a", "b"], ["a", "b", "c"])
    assert not matches(["a", "...", "d"], ["a", "b"])


def test_example_comments_are_read_in_page_order(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("<!-- example: workspaces/example -->\n```console\n$ roc a\none\n...\n$ roc b\n```\n"
                    "```console\n$ not run\n```\n<!-- example: workspaces/example, slow -->\n```console\n"
                    "$ roc c\n```\n")
    quick, slow = sequences(page)
    assert (quick.directory, quick.slow, slow.directory, slow.slow) == ("workspaces/example", False,
                                                                        "workspaces/example", True)
    assert [(c.command, c.expected) for c in quick.commands] == [("roc a", ["one", "..."]), ("roc b", [])]
    assert [(c.command, c.expected) for c in slow.commands] == [("roc c", [])]


def test_live_examples_name_their_graph_files_and_ctrl_c(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("<!-- example file: roc.toml -->\n```toml\n[check]\n```\n"
                    "<!-- example: workspaces/example, graph demo -->\n```console\n$ roc topic hz /r\nrate\n^C\n"
                    "roc: interrupted\n```\n<!-- not run: two machines -->\n```console\n$ a\nb\n```\n"
                    "```console\n$ only a command\n```\n```console\n$ c\nshown, never run\n```\n")
    (live,) = sequences(page)
    assert (live.graph, live.files, live.commands[0].expected) == ("demo", {"roc.toml": "[check]\n"},
                                                                   ["rate", "^C", "roc: interrupted"])
    assert split_at_interrupt(live.commands[0].expected) == (["rate"], ["roc: interrupted"])
    assert split_at_interrupt(["a"]) == (["a"], None)
    assert unchecked_output_blocks(page) == [20]  # the last block


def test_a_recording_waits_as_its_comment_says_and_indented_transcripts_are_unchecked(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("<!-- example: workspaces/example, graph demo, ctrl-c after 4.5 s -->\n```console\n"
                    "$ roc bag record -a\nListening for topics...\n^C\n```\n\nText:\n\n    $ roc pkg list\n"
                    "    demo_py\n\nA command alone:\n\n    roc pkg list\n\n<!-- not run: quoted -->\n\n"
                    "    $ roc a\n    b\n")
    (live,) = sequences(page)
    assert live.commands[0].interrupt_after == 4.5
    assert unchecked_output_blocks(page) == [10]  # the transcript; not the command alone, not the quoted one


def _all_sequences() -> list:
    params = []
    for page in pages():
        for sequence in sequences(page):
            if sequence.graph:
                continue  # tests/docs/test_docs_live_graph.py runs them beside their graph
            marks = [pytest.mark.slow] if sequence.slow else []
            params.append(pytest.param(sequence, id=sequence.name, marks=marks))
    return params


def test_every_console_block_that_shows_output_is_run_or_says_why_not() -> None:
    """Output pasted once drifts from what roc prints: a block showing output is an example that runs
    (beside a live graph if it shows one), or says why it cannot (``<!-- not run: two machines -->``)."""
    unchecked = {str(page.relative_to(REPO)): lines for page in pages() if (lines := unchecked_output_blocks(page))}
    assert not unchecked, f"console blocks with output that are neither run nor say why not (page: lines): {unchecked}"


@pytest.mark.parametrize("sequence", _all_sequences())
def test_the_examples_print_what_the_page_shows(sequence: Sequence, tmp_path: Path) -> None:
    directory = tmp_path / "example"
    shutil.copytree(REPO / sequence.directory, directory, symlinks=True,
                    ignore=shutil.ignore_patterns("build", "install", "log", "__pycache__"))
    (tmp_path / "home").mkdir()
    env = reader_environment(tmp_path / "home")
    for command in sequence.commands:
        result = subprocess.run(["bash", "-c", command.command], cwd=directory, env=env, stdin=subprocess.DEVNULL,
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=600)
        actual = result.stdout.splitlines()
        assert matches(command.expected, actual), (
            f"{sequence.page}:{command.line}: $ {command.command}\n--- the page shows:\n"
            + "\n".join(command.expected) + "\n--- roc printed:\n" + result.stdout)




def test_the_manual_says_what_a_newcomer_needs_to_know() -> None:
    """(The examples of the manual and the README are run by tests/docs/test_docs.py.)"""
    work = " ".join((REPO / "docs" / "commands" / "work.md").read_text().split())
    assert "on the PyPI wheels (which have none) rclcpp built from source as an underlay" in work
    assert "That file is roc's own JSON-lines event format, not colcon's" in work
    bench = (REPO / "bench" / "README.md").read_text()
    assert "/work/" not in bench and "/home/" not in bench
    for script in sorted((REPO / "bench").glob("*.py")):
        assert f"## {script.name}" in bench or f"`{script.name}`" in bench, script.name
    assert "## incremental_bench.py" in bench


def test_the_configuration_page_names_every_table_roc_toml_may_hold() -> None:
    """Issue 51: the list of roc.toml's tables left out the launch systems' tables."""
    from roc.launch.system import HOST_KEYS, PROCESS_KEYS, SYSTEM_KEYS

    listed = " ".join((REPO / "docs" / "configuration.md").read_text().split("## See the effective")[0].split())
    for table in ("[defaults]", "[profile.NAME]", "[profile.NAME.VERB]", "[package.NAME]", "[check]",
                  "[launch.NAME]", "[[launch.NAME.process]]", '[launch.NAME.hosts."H"]'):
        assert f"`{table}`" in listed, table
    for key in (*(k for k in SYSTEM_KEYS if k not in ("process", "hosts")), *PROCESS_KEYS, *HOST_KEYS):
        assert f"`{key}`" in listed, key
