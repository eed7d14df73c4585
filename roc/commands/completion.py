"""``roc completion SHELL``: a completion script made from roc's own argument parser.

Commands and options complete from the parser; package names (positional ones and every value of
options such as ``--packages-select``) complete from ``roc work list -n`` in the current workspace,
options with choices from their choices, other values from file names.
"""

from __future__ import annotations

import argparse
import sys

PACKAGE_METAVARS = {"PKG_NAME", "DEP_NAME"}
PACKAGES = "@packages"  # complete with the workspace's package names
FILES = "@files"  # complete with file names


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("shell", choices=("bash", "zsh", "fish"),
                        help="e.g. 'source <(roc completion bash)' in ~/.bashrc; "
                             "'roc completion fish > ~/.config/fish/completions/roc.fish'")


class Command:
    """What completes after one command path: sub-commands (spelling -> canonical name), options, the
    values of each option that takes some ({option: (count or '*', values)}), and positional values."""

    def __init__(self) -> None:
        self.subcommands: dict[str, str] = {}
        self.options: list[str] = []
        self.values: dict[str, tuple[str, str]] = {}
        self.positional = ""


def _values(action: argparse.Action) -> str:
    """What a value of ``action`` completes from: its choices (or the ``completion`` words a command
    set on it), package names, file names, or nothing (patterns, numbers, free text)."""
    metavar = action.metavar if isinstance(action.metavar, tuple) else (action.metavar,)
    if action.choices or getattr(action, "completion", None):
        return " ".join(map(str, action.choices or action.completion))
    if PACKAGE_METAVARS & set(metavar):
        return PACKAGES
    return FILES if set(metavar) & {None, "PATH", "DIR"} else ""


def _count(action: argparse.Action) -> str:
    if action.nargs in ("*", "+", argparse.REMAINDER):
        return "*"
    return str(action.nargs) if isinstance(action.nargs, int) else "1"


def command_tree(parser: argparse.ArgumentParser, path: tuple[str, ...] = ()) -> dict[tuple[str, ...], Command]:
    """{path: Command} for every command below ``parser``."""
    command = Command()
    tree: dict[tuple[str, ...], Command] = {}
    for action in parser._actions:  # argparse has no public API for walking its parsers
        if isinstance(action, argparse._SubParsersAction):
            canonical = {id(p): name for name, p in reversed(list(action.choices.items()))}
            for name, sub in action.choices.items():
                command.subcommands[name] = canonical[id(sub)]
                if canonical[id(sub)] == name:
                    tree.update(command_tree(sub, path + (name,)))
        elif action.option_strings:
            command.options += action.option_strings
            if action.nargs != 0:
                for option in action.option_strings:
                    command.values[option] = (_count(action), _values(action))
        elif not command.positional and action.nargs != 0:
            command.positional = _values(action)
    tree[path] = command
    return tree


def all_options(parser: argparse.ArgumentParser) -> set[str]:
    """Every option string of every command (not the global ones such as -C, which only go before it)."""
    return {option for path, command in command_tree(parser).items() if path for option in command.options}


def _case_key(path: tuple[str, ...]) -> str:
    return " ".join(path)


def bash_script(tree: dict[tuple[str, ...], Command]) -> str:
    walk, cases = [], []
    for path, command in sorted(tree.items()):
        for spelling, canonical in command.subcommands.items():
            walk.append(f'      "{_case_key(path)}|{spelling}") where="{_case_key(path + (canonical,))}" ;;')
        words = " ".join([*command.subcommands, *command.options])
        by_values: dict[tuple[str, str], list[str]] = {}
        for option, spec in command.values.items():
            by_values.setdefault(spec, []).append(option)
        options = "".join(f'\n        {"|".join(names)}) nargs="{count}" values="{values}" ;;'
                          for (count, values), names in by_values.items())
        positional = command.positional or words
        cases.append(f'    "{_case_key(path)}")\n      words="{words}" positional="{positional}"'
                     + (f'\n      case "$option" in{options}\n      esac' if options else "")
                     + "\n      ;;")
    return f"""# roc bash completion: source <(roc completion bash)
_roc_complete() {{
  local cur="${{COMP_WORDS[COMP_CWORD]}}" where="" words="" positional="" option="" nargs=0 values="" count=0 i
  for ((i = 1; i < COMP_CWORD; i++)); do
    case "$where|${{COMP_WORDS[i]}}" in
{chr(10).join(walk)}
    esac
  done
  # the option the current word may be a value of, and how many values it already has
  for ((i = COMP_CWORD - 1; i > 0; i--)); do
    [[ ${{COMP_WORDS[i]}} == -* ]] && {{ option=${{COMP_WORDS[i]}}; break; }}
    ((count++))
  done
  case "$where" in
{chr(10).join(cases)}
  esac
  if [[ $cur == -* ]]; then
    values=$words
  elif ! [[ -n $option && ( $nargs == "*" || $count -lt $nargs ) ]]; then
    values=$positional
  fi
  case "$values" in
    {PACKAGES}) COMPREPLY=($(compgen -W "$(roc work list -n 2>/dev/null)" -- "$cur")) ;;
    {FILES}) COMPREPLY=($(compgen -f -- "$cur")) ;;
    *) COMPREPLY=($(compgen -W "$values" -- "$cur")) ;;
  esac
}}
complete -F _roc_complete roc
"""


def zsh_script(tree: dict[tuple[str, ...], Command]) -> str:
    """zsh runs the bash function through its bash-completion emulation (hence no variable named
    ``path``, which zsh ties to PATH)."""
    return ("# roc zsh completion: source <(roc completion zsh)\n"
            "autoload -U +X compinit && compinit -u\nautoload -U +X bashcompinit && bashcompinit\n"
            + bash_script(tree))


def _fish_values(values: str) -> str:
    if values == PACKAGES:
        return "-f -a '(roc work list -n 2>/dev/null)'"
    if values == FILES:
        return "-F"
    return f"-f -a '{values}'"


def fish_script(tree: dict[tuple[str, ...], Command]) -> str:
    walk = []
    for path, command in sorted(tree.items()):
        for spelling, canonical in command.subcommands.items():
            walk.append(f'            case "{_case_key(path)}|{spelling}"\n                set path "{_case_key(path + (canonical,))}"')
    lines = [
        "# roc fish completion: roc completion fish > ~/.config/fish/completions/roc.fish",
        "function __roc_path",
        "    set -l path ''",
        "    for word in (commandline -opc)[2..-1]",
        '        switch "$path|$word"',
        *walk,
        "        end",
        "    end",
        "    echo $path",
        "end",
        "# __roc_value_of OPTION SPEC...: whether the current word is a value of OPTION ('*': of any option);",
        "# each SPEC is OPTION:COUNT ('*' for a list) for the options of the command that take values",
        "function __roc_value_of",
        "    set -l wanted $argv[1]",
        "    set -l words (commandline -opc)",
        "    set -l count 0",
        "    for i in (seq (count $words) -1 2)",
        "        if string match -q -- '-*' $words[$i]",
        "            for spec in $argv[2..-1]",
        "                set -l parts (string split ':' -- $spec)",
        '                if test "$parts[1]" = "$words[$i]"',
        '                    test "$wanted" = "*"; or test "$wanted" = "$parts[1]"; or return 1',
        '                    test "$parts[2]" = "*"; or test $count -lt $parts[2]',
        "                    return",
        "                end",
        "            end",
        "            return 1",
        "        end",
        "        set count (math $count + 1)",
        "    end",
        "    return 1",
        "end",
        "complete -c roc -f",
    ]
    for path, command in sorted(tree.items()):
        condition = f"test (__roc_path) = '{_case_key(path)}'"
        specs = " ".join(f"'{option}:{count}'" for option, (count, _) in command.values.items())
        if command.subcommands:
            lines.append(f'complete -c roc -n "{condition}" -a "{" ".join(command.subcommands)}"')
        if command.positional:
            lines.append(f'complete -c roc -n "{condition}; and not __roc_value_of \'*\' {specs}" '
                         f"{_fish_values(command.positional)}")
        for option in command.options:
            flag = f"-l {option[2:]}" if option.startswith("--") else f"-s {option[1:]}"
            if option not in command.values:
                lines.append(f'complete -c roc -n "{condition}" {flag}')
                continue
            count, values = command.values[option]
            lines.append(f'complete -c roc -n "{condition}" {flag} -r {_fish_values(values)}')
            if count != "1":  # the second and later values of a list option
                lines.append(f'complete -c roc -n "{condition}; and __roc_value_of {option} {specs}" '
                             f"{_fish_values(values)}")
    return "\n".join(lines) + "\n"


def run(args: argparse.Namespace) -> int:
    from roc.cli.commands import build_parser

    tree = command_tree(build_parser())
    script = {"bash": bash_script, "zsh": zsh_script, "fish": fish_script}[args.shell](tree)
    sys.stdout.write(script)
    return 0
