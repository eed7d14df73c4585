"""Package selection with colcon's semantics, shared by every verb.

``--packages-ignore*`` remove packages from the graph as if they did not exist; every other option
only marks packages as skipped, so they stay in the graph (ordering, recursive dependencies).
"""

from __future__ import annotations

import argparse
import re
from collections.abc import Callable, Iterable
from pathlib import Path

from roc.errors import UsageError
from roc.messages import did_you_mean, unknown_package, warn
from roc.workspace.dependencies import DependencyIndex
from roc.workspace.package import Package

# Options that take package names. An unknown name in one of IGNORED_WHEN_UNKNOWN is left out with a
# warning, so command lines shared between repositories keep working: colcon warns for --packages-select,
# -skip and -ignore and says nothing for the others. The other options name where a selection starts
# (or ends), which an unknown name leaves without meaning: an error, as in colcon.
IGNORED_WHEN_UNKNOWN = ("packages_select", "packages_skip", "packages_ignore", "packages_select_by_dep",
                        "packages_skip_by_dep", "packages_skip_up_to")
REQUIRED_TO_EXIST = ("packages_up_to", "packages_above", "packages_above_and_dependencies")
# Patterns that match nothing: an error for --packages-up-to-regex (as in colcon), else a warning.
REGEX_OPTIONS = ("packages_ignore_regex", "packages_up_to_regex", "packages_select_regex", "packages_skip_regex")
INTERRUPTED_RESULT = "SIGINT"


def _matches(patterns: Iterable[str] | None, name: str) -> bool:
    return any(re.match(p, name) for p in patterns or ())


def _flag(option: str) -> str:
    return f"--{option.replace('_', '-')}"


def check_selection_arguments(args: argparse.Namespace, names: set[str]) -> None:
    """Unknown package names are left out with a warning or are usage errors (see IGNORED_WHEN_UNKNOWN);
    invalid patterns are usage errors."""
    depth_args = getattr(args, "packages_above_depth", None) or []
    if depth_args:
        if not depth_args[0].isdigit():
            raise UsageError("--packages-above-depth: the first value must be a depth (0, 1, ...), "
                             f"not '{depth_args[0]}'")
    for option in IGNORED_WHEN_UNKNOWN:
        for name in getattr(args, option, None) or []:
            if name not in names and name not in (getattr(args, "packages", None) or []):
                hint = did_you_mean(name, names)
                warn(f"ignoring unknown package '{name}' in {_flag(option)}{'; ' + hint if hint else ''}")
    # the names typed as the verb's own arguments (roc work test PKG...) are meant, never shared: they must exist
    checks = [("", getattr(args, "packages", None) or [])]
    checks += [(option, getattr(args, option, None) or []) for option in REQUIRED_TO_EXIST]
    checks += [("packages_above_depth", depth_args[1:]),
               ("packages_start", [args.packages_start] if args.packages_start else []),
               ("packages_end", [args.packages_end] if args.packages_end else [])]
    for option, values in checks:
        for name in values:
            if name not in names:
                raise UsageError(f"{_flag(option) + ': ' if option else ''}{unknown_package(name, names)}")
    for option in REGEX_OPTIONS:
        for pattern in getattr(args, option, None) or []:
            try:
                re.compile(pattern)
            except re.error as error:
                raise UsageError(f"{_flag(option)}: invalid pattern '{pattern}': {error}") from None
            if not any(re.match(pattern, n) for n in names):
                if option == "packages_up_to_regex":
                    raise UsageError(f"{_flag(option)} '{pattern}' matches no package name; run 'roc work list -n' "
                                     "to see the package names")
                warn(f"{_flag(option)} '{pattern}' matches no package name")


def ignore_packages(args: argparse.Namespace, packages: list[Package]) -> list[Package]:
    ignored = set(getattr(args, "packages_ignore", None) or [])
    patterns = getattr(args, "packages_ignore_regex", None)
    if not ignored and not patterns:
        return packages
    return [p for p in packages if p.name not in ignored and not _matches(patterns, p.name)]


def select_packages(args: argparse.Namespace, ordered: list[Package], build_base: Path | None = None,
                    index: DependencyIndex | None = None) -> set[str]:
    """Names of the packages to process; ``ordered`` is the full topological order."""
    index = index or DependencyIndex(ordered)
    by_name = index.by_name
    deps_of = index.recursive

    selected = set(by_name)

    def up_to(roots: set[str]) -> set[str]:
        keep = set(roots)
        for package in reversed(ordered):
            if package.name in keep:
                keep |= deps_of(package.name).keys()
        return keep

    def above(roots: set[str]) -> set[str]:
        return roots | {p.name for p in ordered if roots & deps_of(p.name).keys()}

    if args.packages_up_to:
        selected &= up_to(set(args.packages_up_to))
    if args.packages_up_to_regex:
        selected &= up_to({n for n in by_name if _matches(args.packages_up_to_regex, n)})
    if args.packages_above:
        selected &= above(set(args.packages_above))
    if args.packages_above_and_dependencies:
        selected &= up_to(above(set(args.packages_above_and_dependencies)))
    if args.packages_above_depth and len(args.packages_above_depth) > 1:
        depth = int(args.packages_above_depth[0])
        roots = set(args.packages_above_depth[1:])
        selected &= roots | {p.name for p in ordered
                             if any(d in roots and level <= depth for d, level in deps_of(p.name).items())}
    if args.packages_select_by_dep:
        wanted = set(args.packages_select_by_dep)
        selected &= {p.name for p in ordered if wanted & deps_of(p.name).keys()}
    if args.packages_skip_by_dep:
        unwanted = set(args.packages_skip_by_dep)
        selected -= {p.name for p in ordered if unwanted & deps_of(p.name).keys()}
    if args.packages_skip_up_to:
        selected -= up_to(set(args.packages_skip_up_to))
    if (args.packages_select_build_failed or args.packages_skip_build_finished
            or getattr(args, "packages_select_test_failures", False)
            or getattr(args, "packages_skip_test_passed", False)):
        selected &= _by_previous_result(args, ordered, build_base or Path("build"))
    if args.packages_select is not None or args.packages_select_regex is not None:
        chosen = set(args.packages_select or [])
        selected &= {n for n in by_name if n in chosen or _matches(args.packages_select_regex, n)}
    if args.packages_skip or args.packages_skip_regex:
        skipped = set(args.packages_skip or [])
        selected -= {n for n in by_name if n in skipped or _matches(args.packages_skip_regex, n)}
    if args.packages_start or args.packages_end:
        selected &= _in_range(args, ordered)
    return selected


def _in_range(args: argparse.Namespace, ordered: list[Package]) -> set[str]:
    names = [p.name for p in ordered]
    start = names.index(args.packages_start) if args.packages_start else 0
    end = names.index(args.packages_end) if args.packages_end else len(names) - 1
    if end < start:
        raise UsageError(
            f"--packages-end '{args.packages_end}' comes before --packages-start '{args.packages_start}' "
            "in topological order; swap them"
        )
    return set(names[start:end + 1])


def previous_build_result(build_base: Path, name: str, verb: str = "build") -> str | None:
    """The result colcon (and roc) stored for the last build (or test) of ``name``: '0' for success."""
    try:
        return (build_base / name / f"colcon_{verb}.rc").read_text().strip()
    except OSError:
        return None


def _by_previous_result(args: argparse.Namespace, ordered: list[Package], build_base: Path) -> set[str]:
    """--packages-select-build-failed, --packages-skip-build-finished and their test counterparts."""
    keep: Callable[[str | None], bool]
    select_failed = args.packages_select_build_failed or getattr(args, "packages_select_test_failures", False)
    verb = "build" if args.packages_select_build_failed or args.packages_skip_build_finished else "test"
    if select_failed:
        keep = lambda result: result not in (None, "0", INTERRUPTED_RESULT)  # noqa: E731
    else:
        keep = lambda result: result != "0"  # noqa: E731
    return {p.name for p in ordered if keep(previous_build_result(build_base, p.name, verb))}
