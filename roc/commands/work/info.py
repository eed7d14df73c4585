"""``roc work info``: package details, like ``colcon info`` (``--format json`` adds the manifest)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument, add_selection_arguments
from roc.errors import RocError, UsageError
from roc.messages import unknown_package
from roc.render import print_json, print_lines
from roc.workspace.package import Package


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("package_names", nargs="*", metavar="PKG_NAME", help="only these packages (default: all)")
    add_format_argument(parser)
    add_selection_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from roc.workspace.load import load_workspace

    workspace = load_workspace(args)
    if not workspace.ordered:  # as colcon info, which fails with "No packages found"
        raise RocError(f"no packages found in {workspace.root}; run roc in a workspace or pass --base-paths")
    by_name = workspace.by_name
    unknown = [n for n in args.package_names if n not in by_name]
    if unknown:
        raise UsageError(unknown_package(unknown[0], by_name))
    packages = sorted(
        (p for p in workspace.selected_in_order() if not args.package_names or p.name in args.package_names),
        key=lambda p: p.name,
    )
    if args.format == "json":
        print_json([package_details(p) for p in packages])
    else:
        print_lines(line for p in packages for line in info_lines(p))
    return 0


def info_lines(package: Package) -> list[str]:
    lines = [f"path: {package.path}", f"  type: {package.type}", f"  name: {package.name}"]
    if package.dependencies:
        lines.append("  dependencies:")
        lines += [f"    {c}: {' '.join(sorted(package.dependencies[c]))}" for c in sorted(package.dependencies)]
    if package.hooks:
        lines.append(f"  hooks: {' '.join(package.hooks)}")
    if package.metadata:
        lines.append("  metadata:")
        lines += [f"    {key}: {package.metadata[key]}" for key in sorted(package.metadata)]
    return lines


def package_details(package: Package) -> dict:
    details = {
        "name": package.name,
        "path": str(package.path),
        "type": package.type,
        "dependencies": {c: sorted(names) for c, names in sorted(package.dependencies.items())},
        "version_constraints": package.constraints,
        "hooks": package.hooks,
        "metadata": package.metadata,
    }
    manifest = package.manifest
    if manifest is not None:
        details["manifest"] = {
            "path": str(manifest.path),
            "format": manifest.format,
            "version": manifest.version,
            "description": manifest.description,
            "maintainers": manifest.maintainers,
            "authors": manifest.authors,
            "licenses": manifest.licenses,
            "urls": [{"type": t, "url": u} for t, u in manifest.urls],
            "build_type": manifest.build_type,
            "dependencies": [
                {"name": d.name, "tag": d.tag, **dict(d.versions),
                 **({"condition": d.condition} if d.condition else {})}
                for d in manifest.dependencies
            ],
            "group_depends": manifest.group_depends,
            "member_of_groups": manifest.member_of_groups,
        }
    return details
