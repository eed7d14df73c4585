"""Read generated PowerShell scripts without PowerShell: the PowerShell tree-sitter grammar parses them,
and these helpers list what a script does (commands, assignments, environment changes)."""

from __future__ import annotations

from pathlib import Path

import tree_sitter
import tree_sitter_powershell

from roc.environment.dsv import resolve_operations

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


def check_package_scripts(install: Path, packages: list[str], merged: bool) -> None:
    """Each package.ps1 and hook .ps1 parses and makes the changes its .dsv describes, below its own
    prefix (found from the script's place: two or three directories up)."""
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
