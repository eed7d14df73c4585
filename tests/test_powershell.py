"""The PowerShell scripts (setup.ps1, local_setup.ps1, package.ps1, hook .ps1).

No PowerShell interpreter can be installed on this machine (none in its package registries), so these
tests cannot source the scripts. They parse every generated script with the PowerShell tree-sitter
grammar and check, on the parse tree, that each script does what its sh twin does: the same
variables, paths and package order.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from build_helpers import BIN, copy_fixture, in_sourced_shell, roc
from roc.environment.dsv import Operation, resolve_operations
from roc.shell.scripts import render

tree_sitter = pytest.importorskip("tree_sitter")
tree_sitter_powershell = pytest.importorskip("tree_sitter_powershell")
PARSER = tree_sitter.Parser(tree_sitter.Language(tree_sitter_powershell.language()))
QUOTES = "'\u2018\u2019\u201a\u201b"


def parse(text: str):
    tree = PARSER.parse(text.encode())
    assert not tree.root_node.has_error, text
    return tree.root_node


def _value(node) -> str:
    """A string literal's value, a variable's name (``$x``), or the raw text of anything else."""
    text = node.text.decode()
    if node.type == "string_literal" and text[0] in QUOTES:
        body = text[1:-1]
        for quote in QUOTES:
            body = body.replace(quote * 2, quote)
        return body
    return text


def _leaves(node) -> list[str]:
    """The literals and variables of an expression, left to right."""
    if node.type in ("string_literal", "variable"):
        return [_value(node)]
    return [leaf for child in node.children for leaf in _leaves(child)]


def statements(text: str) -> list[tuple[str, ...]]:
    """The script's commands (name, arguments...) and assignments ("=", variable, terms...) in the
    order they appear, outside function definitions."""
    found: list[tuple[str, ...]] = []

    def visit(node) -> None:
        if node.type == "function_statement":
            return
        if node.type == "assignment_expression":
            target, _, value = node.children
            found.append(("=", *_leaves(target), *_leaves(value)))
            visit(value)
            return
        if node.type == "command":
            # "name arguments..." or, for a script run with an operator, ". $path" / "& $path"
            parts = [c.text.decode() for c in node.children if c.type != "command_elements"]
            arguments = [leaf for c in node.children if c.type == "command_elements" for leaf in _leaves(c)]
            found.append((*parts, *arguments))
        for child in node.children:
            visit(child)

    visit(parse(text))
    return found


def applied(text: str) -> list[tuple[str, str, str]]:
    """``(function, variable, path)`` for each list change or set of a package script, the path with
    ``PREFIX`` for the package prefix (the scripts build each path in ``$_roc_package_path`` first)."""
    path, changes = None, []
    for statement in statements(text):
        if statement[:2] == ("=", "$_roc_package_path"):
            path = "".join("PREFIX" if term == "$_roc_package_prefix" else term for term in statement[2:])
        elif statement[0].startswith("_roc_") and statement[-1] == "$_roc_package_path" or \
                statement[0] == "_roc_set":
            changes.append((statement[0], statement[1], path))
    return changes


def expected_changes(prefix: Path, dsv: Path) -> list[tuple[str, str, str]]:
    functions = {"prepend-non-duplicate": "_roc_prepend_unique", "prepend-non-duplicate-if-exists":
                 "_roc_prepend_unique", "append-non-duplicate": "_roc_append_unique", "set": "_roc_set",
                 "set-if-unset": "_roc_set"}
    return [(functions[op.kind], op.name, "PREFIX" + (f"/{value}" if value else ""))
            for op in resolve_operations(prefix, dsv) if op.kind != "source" for value in op.values]


def test_the_parser_finds_errors():
    """The checks below mean something only if the grammar rejects broken PowerShell."""
    for broken in ("if ($a { . $b }\n", "$x = 'unterminated\n", "function f { \n"):
        assert PARSER.parse(broken.encode()).root_node.has_error, broken


def test_quoting_keeps_any_path():
    """Single quotes, PowerShell's typographic quotes, $, backticks and spaces in a path survive."""
    odd = "/w s/it's ‘x’ $HOME `n \"q\""
    text = render("setup.ps1.j2", underlays=[odd])
    assert ("=", "$_roc_setup_script", f"{odd}/local_setup.ps1") in statements(text)


def test_every_dsv_operation_kind():
    operations = [Operation("prepend-non-duplicate", "PATH", ("bin", "")),
                  Operation("prepend-non-duplicate-if-exists", "PYTHONPATH", ("lib/site",)),
                  Operation("append-non-duplicate", "CMAKE_MODULE_PATH", ("/abs/cmake",)),
                  Operation("set", "ROBOT", ("share/robot.yaml",)),
                  Operation("set-if-unset", "RMW_IMPLEMENTATION", ("rmw_fastrtps_cpp",)),
                  Operation("source", "share/p/hook/user.ps1")]
    text = render("package.ps1.j2", package="p", prefix="/nowhere", operations=operations, up="../..")
    assert applied(text) == [
        ("_roc_prepend_unique", "PATH", "PREFIX/bin"), ("_roc_prepend_unique", "PATH", "PREFIX"),
        ("_roc_prepend_unique", "PYTHONPATH", "PREFIX/lib/site"), ("_roc_append_unique", "CMAKE_MODULE_PATH", "/abs/cmake"),
        ("_roc_set", "ROBOT", "PREFIX/share/robot.yaml"), ("_roc_set", "RMW_IMPLEMENTATION", "PREFIX/rmw_fastrtps_cpp")]
    found = statements(text)
    assert ("_roc_set", "ROBOT", "$_roc_package_path", "share/robot.yaml") in found  # the text when no such file
    assert ("Test-Path", "$_roc_package_path") in found  # the if-exists condition
    assert ("=", "$_roc_package_script", "$_roc_package_prefix", "/share/p/hook/user.ps1") in found
    assert (".", "$_roc_package_script") in found
    assert "if (-not [Environment]::GetEnvironmentVariable('RMW_IMPLEMENTATION')) { _roc_set" in text


@pytest.mark.parametrize("merged", [False, True])
def test_scripts_parse_and_match_their_sh_twins(tmp_path, merged):
    ws = copy_fixture("build_small", tmp_path / "ws")
    result = roc("work", "build", *(["--merge-install"] if merged else []), cwd=ws)
    assert result.returncode == 0, result.stdout + result.stderr
    install = ws / "install"
    scripts = sorted(install.rglob("*.ps1"))
    packages = ["core", "app", "plain", "pyp"]  # the order of local_setup.sh
    assert len(scripts) == 2 + len(packages) + len(list(install.rglob("hook/*.dsv")))
    for script in scripts:
        parse(script.read_text())

    # local_setup.ps1: COLCON_PREFIX_PATH, then every package.ps1 in dependency order.
    local_setup = statements((install / "local_setup.ps1").read_text())
    assert local_setup[0] == ("=", "$_roc_base", "$PSScriptRoot")
    assert ("_roc_prepend_unique", "COLCON_PREFIX_PATH", "$_roc_base") in local_setup
    sourced = [s[2] for s in local_setup if s[:2] == ("Join-Path", "$_roc_base")]
    assert sourced == [f"{'' if merged else name + '/'}share/{name}/package.ps1" for name in packages]
    sh_order = [line for line in (install / "local_setup.sh").read_text().splitlines() if "package.sh" in line]
    assert [line.split("/share/")[1].split("/")[0] for line in sh_order[::2]] == packages

    # Each package.ps1 and hook script makes the changes its .dsv describes, below its own prefix.
    for name in packages:
        prefix = install if merged else install / name
        share = prefix / "share" / name
        package_ps1 = (share / "package.ps1").read_text()
        assert statements(package_ps1)[0][:3] == ("=", "$_roc_package_prefix", "$PSScriptRoot")
        assert "'../..'" in package_ps1
        assert applied(package_ps1) == expected_changes(prefix, share / "package.dsv")
        assert applied(package_ps1), name
        for hook in (share / "hook").glob("*.ps1"):
            assert "'../../..'" in hook.read_text()
            assert applied(hook.read_text()) == expected_changes(prefix, hook.with_suffix(".dsv"))

    # setup.ps1: its own local_setup.ps1, found next to it.
    assert statements((install / "setup.ps1").read_text())[-3:-1] == [
        ("Join-Path", "$PSScriptRoot", "local_setup.ps1"), (".", "$_roc_setup_script")]


def test_setup_ps1_chains_the_underlays(tmp_path):
    underlay = copy_fixture("build_small", tmp_path / "under lay")
    overlay = tmp_path / "overlay"
    (overlay / "src").mkdir(parents=True)
    os.rename(underlay / "src" / "app", overlay / "src" / "app")
    assert roc("work", "build", cwd=underlay).returncode == 0
    built = in_sourced_shell(overlay, f"{BIN / 'roc'} work build", setup=str(underlay / "install" / "setup.bash"))
    assert built.returncode == 0, built.stdout + built.stderr
    chained = [s[2] for s in statements((overlay / "install" / "setup.ps1").read_text())
               if s[:2] == ("=", "$_roc_setup_script") and len(s) == 3]
    assert chained == [f"{underlay}/install/local_setup.ps1"]
