"""The ``roc`` command: argument parsing, dispatch and the error convention.

Exit codes: 0 ok, 1 failure, 2 usage error, 130 interrupted. Errors are one line on stderr (after the
ros2 CLI's own line for the same error, where roc says more than it: RocError.ros2_line); a Python
traceback only with ``--debug`` or ``ROC_DEBUG=1``. Command modules are imported only when run, so
that start-up stays light.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from roc.cli.commands import (
    CONFIGURED_VERBS,
    Parser,
    build_parser,
    command_module,
    requested_command,
)
from roc.errors import EXIT_FAILURE, EXIT_INTERRUPTED, EXIT_USAGE, RocError


def _early_value(argv: list[str], option: str) -> str | None:
    """The value of ``option`` (``-C DIR``, ``--profile NAME``) before argparse runs."""
    for index, word in enumerate(argv):
        if word == option and index + 1 < len(argv):
            return argv[index + 1]
        if word.startswith(option + "="):
            return word.split("=", 1)[1]
    return None


def _early_values(argv: list[str], option: str) -> list[str] | None:
    """The values after ``option`` up to the next option (``--metas A B``), None when it is absent."""
    if option not in argv:
        return None
    values = []
    for word in argv[argv.index(option) + 1:]:
        if word.startswith("-"):
            break
        values.append(word)
    return values


def _apply_workspace_configuration(parser: Parser, path: tuple[str, ...], argv: list[str]):
    """Make roc.toml / colcon defaults the defaults of the command's options (the command line wins)."""
    from roc.config import apply_configuration, load_configuration
    from roc.workspace.root import find_workspace_root

    cwd = Path.cwd()
    root = find_workspace_root(cwd) or cwd
    metas = _early_values(argv, "--metas")
    config = load_configuration(root, path[-1], _early_value(argv, "--profile"), metas,
                                ignore_user_meta="--ignore-user-meta" in argv)
    apply_configuration(parser.leaves[path], config)
    return config


def _with_help_pointer(error: RocError, path: tuple[str, ...]) -> str:
    """A usage error (one the daemon raised included) points at the help of the command it was given
    to, unless it already says where to look (as argparse's errors do, see Parser.error)."""
    message = str(error)
    if error.exit_code == EXIT_USAGE and path and "see '" not in message:
        message += f" (see '{' '.join(('roc', *path))} --help')"
    return message


def main(argv: list[str] | None = None) -> int:
    debug = os.environ.get("ROC_DEBUG") == "1" or "--debug" in (argv if argv is not None else sys.argv[1:])
    path: tuple[str, ...] = ()
    try:
        from roc.rclpy_guard import guard_rclpy_import

        guard_rclpy_import()  # two distributions sourced: a one-line error where a verb would load rclpy
        argv = list(sys.argv[1:] if argv is None else argv)
        first_word = next((i for i, w in enumerate(argv) if not w.startswith("-") and (i == 0 or argv[i - 1] != "-C")),
                          len(argv))
        directory = _early_value(argv[:first_word], "-C")
        if directory:
            try:
                os.chdir(directory)
            except OSError as error:
                raise RocError(f"-C {directory}: {error.strerror}") from None
        parser = build_parser(argv)
        path = requested_command(argv)
        config = None
        if path in parser.leaves and path[0] == "work" and path[-1] in CONFIGURED_VERBS:
            config = _apply_workspace_configuration(parser, path, argv)
        from roc.cli.options import PASSTHROUGH_OPTIONS

        if any(token in argv for token in PASSTHROUGH_OPTIONS):
            from roc.cli.options import rewrite_passthrough
            from roc.commands.completion import all_options

            argv = rewrite_passthrough(argv, all_options(parser))
        command_words = argv[first_word:]  # the command without roc's global options (-C is already applied)
        args = parser.parse_args(argv)
        args.configuration = config
        args.command_words = command_words
        module = getattr(args, "_module", None)
        if module is None:
            (getattr(args, "_group", None) or parser).print_help(sys.stderr)
            return EXIT_USAGE
        return command_module(module).run(args)
    except RocError as error:
        if debug:
            raise
        if error.ros2_line:
            print(error.ros2_line, file=sys.stderr)
        print(f"roc: error: {_with_help_pointer(error, path)}", file=sys.stderr)
        return error.exit_code
    except KeyboardInterrupt:
        print("roc: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # The reader went away (e.g. `roc work list | head`): not an error worth a message.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as error:  # a path roc cannot create, read or write
        if debug:
            raise
        where = f"{error.filename}: " if error.filename else ""
        print(f"roc: error: {where}{error.strerror or error}; check the path and its permissions", file=sys.stderr)
        return EXIT_FAILURE
    except Exception as error:  # noqa: BLE001 - last resort: one line, details with --debug
        if debug:
            raise
        print(f"roc: error: internal error: {type(error).__name__}: {error} (run with --debug for details)",
              file=sys.stderr)
        return EXIT_FAILURE
