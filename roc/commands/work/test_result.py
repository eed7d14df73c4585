"""``roc work test-result``: the results of the last tests, a drop-in for ``colcon test-result``."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from roc.cli.options import add_format_argument
from roc.errors import EXIT_FAILURE, UsageError
from roc.render import print_json, print_lines


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add = parser.add_argument
    add("--test-result-base", default="build", help="the base path of all test results (default: build)")
    add("--all", action="store_true", help="show all result files (also those without errors or failures)")
    add("--verbose", action="store_true", help="show the details of each error and failure")
    add("--result-files-only", action="store_true",
        help="print only the paths of the result files (with --all, also those without errors or failures)")
    delete = parser.add_mutually_exclusive_group()
    delete.add_argument("--delete", action="store_true", help="delete all result files (asks first)")
    delete.add_argument("--delete-yes", action="store_true", help="delete all result files without asking")
    add("--junit-xml", metavar="FILE", help="also write every result merged into one JUnit XML report")
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    from roc.testing.results import collect_results, merged_junit, summarize

    base = Path(args.test_result_base)
    if not base.is_dir():
        raise UsageError(f"--test-result-base: '{base}' {'is not a directory' if base.exists() else 'does not exist'}")
    if args.delete or args.delete_yes:
        return _delete(base, args.delete_yes)
    results = collect_results(base, details=args.verbose or args.format == "json")
    summary = summarize(results)
    shown = [result for result in results if args.all or not result.ok]
    if args.junit_xml:
        from roc.fsutil import write_text_atomic

        write_text_atomic(Path(args.junit_xml), merged_junit(results, base).decode())
    if args.format == "json":
        print_json({"results": [result.as_dict() for result in (results if args.all else shown)],
                    "summary": {key: value for key, value in summary.as_dict().items()
                                if key not in ("path", "details", "not_started")}})
    elif args.result_files_only:
        print_lines(result.path for result in shown)
    else:
        lines = []
        for result in shown:
            lines.append(result.line())
            lines += [f"  {reason}" for reason in result.not_started]  # which tests never started, and why
            if args.verbose:
                for detail in result.details:
                    lines += [f"{'-' if i == 0 else ' '} {line}" for i, line in enumerate(detail.splitlines())]
        print_lines([*lines, *([""] if shown else []), summary.line()])
    return 0 if summary.ok else EXIT_FAILURE


def _delete(base: Path, yes: bool) -> int:
    from roc.cli.confirm import confirm
    from roc.testing.results import collect_results

    files: set[str] = set()
    collect_results(base, files=files)
    if not files:
        print_lines(["No result files found to delete"])
        return 0
    print_lines(f"- {path}" for path in sorted(files))
    if not yes and not confirm(f"Delete these {len(files)} files?", "--delete-yes"):
        print_lines(["Aborted"])
        return 0
    for path in sorted(files):
        os.remove(path)
    print_lines([f"Deleted {len(files)} files"])
    return 0
