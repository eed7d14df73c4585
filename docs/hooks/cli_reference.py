"""The manual's CLI reference, generated from roc's argument parser at build time (an MkDocs hook).

``roc.cli.commands.build_parser()`` is the one source: every command group gets a page
``reference/<group>.md`` with each verb's synopsis, arguments, options, choices, defaults and help text,
so the reference cannot drift from ``--help``. The pages are added to the ``CLI reference`` section of
the navigation in the order of the command table, so a new command group appears without any edit here.

Anchors, for the hand-written pages to link to: ``#roc-topic-echo`` (a verb),
``#roc-topic-echo--csv`` (an option), ``#roc-topic-echo-topic_name`` (a positional argument). Option
groups that several verbs of a page share (``discovery``, ``package selection``) are written once, at
the end of the page, with anchors such as ``#discovery--packages-up-to``.
"""

from __future__ import annotations

import argparse
import copy
import html
import re
from collections import Counter
from dataclasses import dataclass

from roc.cli import commands

SECTION = "CLI reference"
WIDTH = 100  # argparse's formatter width (it wraps nothing we print, but needs one)
# Guide pages whose name is not commands/<group>.md (linked only when the page exists).
GUIDES = {
    "completion": "getting-started.md#shell-completion",
    "pkg": "commands/launch.md",
    "run": "commands/launch.md",
    "launch": "commands/launch.md",
}
_MARKDOWN_SPECIAL = re.compile(r"([\\`*_\[\]])")


def text(value: str) -> str:
    """Help text as Markdown that shows exactly that text."""
    return _MARKDOWN_SPECIAL.sub(r"\\\1", html.escape(value, quote=False))


def cell(value: str) -> str:
    """Help text for a table cell (a ``|`` would end the cell)."""
    return text(value).replace("|", "\\|")


def code(value: str) -> str:
    return f"``{value}``" if "`" in value else f"`{value}`"


@dataclass
class Leaf:
    path: tuple[str, ...]
    aliases: tuple[str, ...]
    parser: argparse.ArgumentParser

    @property
    def anchor(self) -> str:
        return "-".join(("roc", *self.path))

    @property
    def name(self) -> str:
        return " ".join(("roc", *self.path))


def leaves_by_group(parser: argparse.ArgumentParser) -> dict[str, list[Leaf]]:
    """The parser's verbs by top-level command group, in the command table's order."""
    leaves: dict[tuple[str, ...], argparse.ArgumentParser] = parser.leaves  # type: ignore[attr-defined]
    groups: dict[str, list[Leaf]] = {}
    for path, aliases, _module, _help in commands.COMMANDS:
        groups.setdefault(path[0], [])
        if path in leaves:
            groups[path[0]].append(Leaf(path, tuple(aliases), leaves[path]))
    return groups


def _formatter(parser: argparse.ArgumentParser) -> argparse.HelpFormatter:
    return argparse.HelpFormatter(parser.prog, width=WIDTH)


def _visible(group: argparse._ArgumentGroup) -> list[argparse.Action]:
    return [a for a in group._group_actions
            if a.help != argparse.SUPPRESS and not isinstance(a, (argparse._HelpAction, argparse._SubParsersAction))]


def _shareable(group: argparse._ArgumentGroup) -> bool:
    """Groups of a title of their own (``discovery``), not argparse's ``options`` and ``positional arguments``."""
    return group.title not in ("options", "positional arguments", "optional arguments") and bool(_visible(group))


def _signature(group: argparse._ArgumentGroup) -> tuple:
    """What makes two option groups the same: their title and every option's strings and help."""
    return (group.title, tuple((tuple(a.option_strings), a.dest, a.help) for a in _visible(group)))


def _slug(title: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", title.lower()).strip("-")


def _details(action: argparse.Action, formatter: argparse.HelpFormatter) -> list[str]:
    """The help text, choices and default of one argument."""
    help_text = formatter._expand_help(action) if action.help else ""
    lines = [text(help_text) if help_text else "(no help text)"]
    facts = []
    if action.choices is not None and not isinstance(action.choices, dict):
        facts.append("choices: " + ", ".join(code(str(c)) for c in action.choices))
    default = action.default
    shown = default not in (None, False, [], argparse.SUPPRESS) and not isinstance(
        action, (argparse._StoreTrueAction, argparse._StoreFalseAction, argparse._VersionAction))
    if shown and "default" not in help_text.lower():
        facts.append("default: " + code(" ".join(map(str, default)) if isinstance(default, list) else str(default)))
    if facts:
        lines.append("; ".join(facts))
    return lines


def _argument(action: argparse.Action, formatter: argparse.HelpFormatter, prefix: str) -> list[str]:
    """One argument as a definition list entry with an anchor."""
    if action.option_strings:
        if action.choices is not None and action.metavar is None and action.nargs != 0:
            action = copy.copy(action)  # a name for the value; the choices are listed below
            action.metavar = action.dest.upper()
        invocation = formatter._format_action_invocation(action)
        term = ", ".join(code(part) for part in invocation.split(", "))
        anchor = prefix + max(action.option_strings, key=len)
    else:
        term = code(formatter._format_args(action, formatter._get_default_metavar_for_positional(action)))
        anchor = f"{prefix}-{action.dest.lower()}"
    body = _details(action, formatter)
    return [f"{term} {{ #{anchor} }}", f":   {body[0]}", *(f"\n    {line}" for line in body[1:]), ""]


def _group(group: argparse._ArgumentGroup, formatter: argparse.HelpFormatter, prefix: str) -> list[str]:
    lines = [f"**{text(str(group.title))}**", ""]
    if group.description:
        lines += [text(group.description), ""]
    for action in _visible(group):
        lines += _argument(action, formatter, prefix)
    return lines


def _synopsis(leaf: Leaf) -> str:
    formatter = _formatter(leaf.parser)
    words = [leaf.name]
    if any(a.option_strings and a.help != argparse.SUPPRESS and not isinstance(a, argparse._HelpAction)
           for a in leaf.parser._actions):
        words.append("[OPTIONS]")
    for action in leaf.parser._positionals._group_actions:
        words.append(formatter._format_args(action, formatter._get_default_metavar_for_positional(action)))
    return " ".join(words)


def group_page(group: str, leaves: list[Leaf], guide: str | None) -> str:
    """The reference page of one command group."""
    description = next(h for p, _a, _m, h in commands.COMMANDS if p == (group,))
    lines = [f"# roc {group}", "", text(description), "",
             "Generated from roc's argument parser: the same text as `--help`."]
    if guide:
        lines[-1] += f" What the verbs are for, with worked examples: [the guide to roc {group}](../{guide})."
    lines.append("")
    counts = Counter(_signature(g) for leaf in leaves for g in leaf.parser._action_groups if _shareable(g))
    shared = {sig: _slug(str(sig[0])) for sig, n in counts.items() if n > 1}
    if len(set(shared.values())) < len(shared):  # two different groups with one title: number them
        shared = {sig: f"{slug}-{i}" for i, (sig, slug) in enumerate(shared.items(), 1)}
    if len(leaves) > 1:
        lines += ["| command | what it does |", "| --- | --- |"]
        lines += [f"| [{code(leaf.name)}](#{leaf.anchor}) | {cell(leaf.parser.description or '')} |" for leaf in leaves]
        lines.append("")
    for leaf in leaves:
        formatter = _formatter(leaf.parser)
        lines += [f"## {leaf.name} {{ #{leaf.anchor} }}", ""]
        if leaf.aliases:
            lines += ["Alias: " + ", ".join(code(" ".join(("roc", *leaf.path[:-1], a))) for a in leaf.aliases), ""]
        lines += [text(leaf.parser.description or ""), "", "```text", _synopsis(leaf), "```", ""]
        for group_ in leaf.parser._action_groups:
            if not _visible(group_):
                continue
            if _signature(group_) in shared:
                slug = shared[_signature(group_)]
                lines += [f"**{text(str(group_.title))}**: [the {text(str(group_.title))} options](#{slug}).", ""]
            else:
                lines += _group(group_, formatter, leaf.anchor)
    written = set()
    for leaf in leaves:
        for group_ in leaf.parser._action_groups:
            sig = _signature(group_)
            if sig in shared and sig not in written:
                written.add(sig)
                lines += [f"## {text(str(group_.title)).capitalize()} options {{ #{shared[sig]} }}", ""]
                lines += _group(group_, _formatter(leaf.parser), shared[sig])[2:]
    return "\n".join(lines).rstrip() + "\n"


def index_page(parser: argparse.ArgumentParser, groups: dict[str, list[Leaf]], guides: dict[str, str]) -> str:
    """The reference's first page: roc's global options and its command groups."""
    formatter = _formatter(parser)
    lines = ["# CLI reference", "",
             "Every command of roc, generated from its argument parser when the manual is built: the same "
             "options, choices, defaults and help text as `roc ... --help`.", "",
             "```text", "roc [OPTIONS] COMMAND ...", "```", "", "**global options** (before the command)", ""]
    for action in parser._actions:
        if action.option_strings and not isinstance(action, argparse._HelpAction):
            lines += _argument(action, formatter, "roc")
    lines += ["| command group | what it is for | guide |", "| --- | --- | --- |"]
    for group in groups:
        description = next(h for p, _a, _m, h in commands.COMMANDS if p == (group,))
        guide = f"[guide](../{guides[group]})" if group in guides else ""
        lines.append(f"| [{code('roc ' + group)}]({group}.md) | {cell(description)} | {guide} |")
    return "\n".join(lines) + "\n"


def reference_pages(existing: set[str]) -> dict[str, str]:
    """``{path under docs/: Markdown}`` of the whole reference; ``existing`` are the manual's pages,
    for the links to each group's guide."""
    parser = commands.build_parser()
    groups = leaves_by_group(parser)
    guides = {}
    for group in groups:
        guide = GUIDES.get(group, f"commands/{group}.md")
        if guide.split("#")[0] in existing:
            guides[group] = guide
    pages = {"reference/index.md": index_page(parser, groups, guides)}
    for group, leaves in groups.items():
        pages[f"reference/{group}.md"] = group_page(group, leaves, guides.get(group))
    return pages


def _nav_path(entry) -> str:
    """The page of a nav entry: ``path`` or ``{title: path}``."""
    return entry if isinstance(entry, str) else next(iter(entry.values()))


# ---- MkDocs hook events -------------------------------------------------------------------------


def on_files(files, config):
    """Add the generated pages, and list them in the navigation's ``CLI reference`` section."""
    import importlib
    import sys

    from mkdocs.structure.files import File

    global commands
    for name in [m for m in sys.modules if m.startswith("roc.")]:  # mkdocs serve: the parser as it is now
        del sys.modules[name]
    commands = importlib.import_module("roc.cli.commands")
    existing = {f.src_uri for f in files.documentation_pages()}
    pages = reference_pages(existing)
    for path, markdown in pages.items():
        files.append(File.generated(config, path, content=markdown))
    titles = {path: "Overview" if path.endswith("/index.md") else f"roc {path[len('reference/'):-len('.md')]}"
              for path in pages}
    for entry in config["nav"] or []:
        if isinstance(entry, dict) and SECTION in entry:
            kept = [e for e in entry[SECTION] or [] if _nav_path(e) not in pages]
            entry[SECTION] = kept + [{titles[path]: path} for path in pages]
            break
    else:
        raise ValueError(f"mkdocs.yml: the nav has no '{SECTION}' section for the generated reference")
    return files
