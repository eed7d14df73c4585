"""``roc completion SHELL``: a completion script made from roc's own argument parser.

Commands and options complete from the parser; package names (positional ones and every value of
options such as ``--packages-select``) complete from ``roc work list -n`` in the current workspace,
options with choices from their choices, other values from file names. Graph names (topics, nodes,
services, actions, parameters, tf frames) and interface types complete from ``roc completion --names
KIND`` (roc.commands.completion_names), which asks a running roc daemon and never starts one; which
argument takes which kind of name is told by its name (``topic_name``, ``service_type``, ...).
Every positional argument completes by its place among the words typed after the command.
"""

from __future__ import annotations

import argparse
import sys

from roc.errors import UsageError

PACKAGE_METAVARS = {"PKG_NAME", "DEP_NAME"}
PACKAGES = "@packages"  # complete with the workspace's package names
FILES = "@files"  # complete with file names
GRAPH = "@graph:"  # complete with ``roc completion --names KIND``; the kind follows
# the kind of graph name (roc.commands.completion_names.KINDS) each argument takes, by its dest
GRAPH_NAMES = {
    "topic_name": "topics", "topics": "topics", "topic": "topics", "node_name": "nodes",
    "container_node_name": "nodes", "service_name": "services", "action_name": "actions",
    "topic_type": "msg-types", "message_type": "msg-types", "service_type": "srv-types",
    "action_type": "action-types", "type": "types", "parameter_name": "params", "parameter_names": "params",
    "assignments": "params", "source_frame": "frames", "target_frame": "frames", "frames": "frames",
    "parent_frame": "frames", "child_frame": "frames"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from roc.commands.completion_names import KINDS

    parser.add_argument("shell", nargs="?", choices=("bash", "zsh", "fish"),
                        help="e.g. 'source <(roc completion bash)' in ~/.bashrc; "
                             "'roc completion fish > ~/.config/fish/completions/roc.fish'")
    parser.add_argument("--names", choices=KINDS, help="print the names of this kind a completion offers "
                                                       "(what the scripts call; from a running daemon only)")
    parser.add_argument("--node", help="with --names params: the node whose parameters to print")


class Command:
    """What completes after one command path: sub-commands (spelling -> canonical name), options, the
    values of each option that takes some ({option: (count or '*', values)}), and the values of each
    positional argument in order ([(count, values)], count 1, '?', '*' or '+')."""

    def __init__(self) -> None:
        self.subcommands: dict[str, str] = {}
        self.options: list[str] = []
        self.values: dict[str, tuple[str, str]] = {}
        self.positionals: list[tuple[str, str]] = []


def _values(action: argparse.Action) -> str:
    """What a value of ``action`` completes from: its choices (or the ``completion`` words a command
    set on it), graph names, package names, file names, or nothing (patterns, numbers, free text)."""
    metavar = action.metavar if isinstance(action.metavar, tuple) else (action.metavar,)
    words = action.choices or getattr(action, "completion", None)
    if words:
        return " ".join(map(str, words))
    if action.dest in GRAPH_NAMES:
        return GRAPH + GRAPH_NAMES[action.dest]
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
        elif action.nargs != 0:
            count = action.nargs if action.nargs in ("?", "*", "+") else "1"
            command.positionals.append((str(count), _values(action)))
    tree[path] = command
    return tree


def all_options(parser: argparse.ArgumentParser) -> set[str]:
    """Every option string of every command (not the global ones such as -C, which only go before it)."""
    return {option for path, command in command_tree(parser).items() if path for option in command.options}


def _case_key(path: tuple[str, ...]) -> str:
    return " ".join(path)


def _bash_spec(path: tuple[str, ...], command: Command) -> str:
    """One arm of _roc_spec: the command's words, its positionals, and the count and values of each
    option that takes values."""
    words = " ".join([*command.subcommands, *command.options])
    by_values: dict[tuple[str, str], list[str]] = {}
    for option, spec in command.values.items():
        by_values.setdefault(spec, []).append(option)
    options = "".join(f'\n        {"|".join(names)}) nargs="{count}" values="{values}" ;;'
                      for (count, values), names in by_values.items())
    positionals = " ".join(f'"{count}|{values}"' for count, values in command.positionals)
    return (f'    "{_case_key(path)}")\n      words="{words}" positionals=({positionals})'
            + (f'\n      case "$2" in{options}\n      esac' if options else "") + "\n      ;;")


def bash_script(tree: dict[tuple[str, ...], Command]) -> str:
    walk = []
    for path, command in sorted(tree.items()):
        for spelling, canonical in command.subcommands.items():
            target = _case_key(path + (canonical,))
            walk.append(f'      "{_case_key(path)}|{spelling}") where="{target}"; start=$((i + 1)) ;;')
    arms = "\n".join(_bash_spec(path, command) for path, command in sorted(tree.items()))
    return f"""# roc bash completion: source <(roc completion bash)
# _roc_spec PATH OPTION: the words, positionals and (for OPTION) nargs and values of command PATH
_roc_spec() {{
  words="" positionals=() nargs=0 values=""
  case "$1" in
{arms}
  esac
}}
_roc_complete() {{
  local cur="${{COMP_WORDS[COMP_CWORD]}}" where="" start=1 words="" positionals=() nargs=0 values="" i word
  local option="" pending=0 position=0 spec count kind node=() given=()
  for ((i = 1; i < COMP_CWORD; i++)); do
    case "$where|${{COMP_WORDS[i]}}" in
{chr(10).join(walk)}
    esac
  done
  # the words after the command: options, their values, and positionals (counted)
  for ((i = start; i < COMP_CWORD; i++)); do
    word=${{COMP_WORDS[i]}}
    if [[ $word == -* ]]; then
      _roc_spec "$where" "$word"; option=$word pending=$nargs
    elif [[ $pending == "*" ]]; then
      :
    elif ((pending > 0)); then
      ((pending--))
    else
      given+=("$word"); ((position++))
    fi
  done
  _roc_spec "$where" "$option"
  if [[ $cur == -* ]]; then
    values=$words
  elif [[ -n $option && ( $pending == "*" || $pending -gt 0 ) ]]; then
    :  # a value of the option
  else
    values=$words
    for spec in "${{positionals[@]}}"; do
      count=${{spec%%|*}}
      if [[ $count == "*" || $count == "+" ]] || ((position == 0)); then
        values=${{spec#*|}}; break
      fi
      ((position--))
    done
  fi
  case "$values" in
    {PACKAGES}) COMPREPLY=($(compgen -W "$(roc work list -n 2>/dev/null)" -- "$cur")) ;;
    {FILES}) COMPREPLY=($(compgen -f -- "$cur")) ;;
    {GRAPH}*)
      kind=${{values#{GRAPH}}}
      [[ $kind == params ]] && node=(--node "${{given[0]}}")
      COMPREPLY=($(compgen -W "$(roc completion --names "$kind" "${{node[@]}}" 2>/dev/null)" -- "$cur")) ;;
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


def _fish_values(values: str, specs: str = "") -> str:
    if values == PACKAGES:
        return "-f -a '(roc work list -n 2>/dev/null)'"
    if values == FILES:
        return "-F"
    if values.startswith(GRAPH):
        kind = values[len(GRAPH):]
        node = f" --node (__roc_positionals {specs.replace(chr(39), chr(34))})[1]" if kind == "params" else ""
        return f"-f -a '(roc completion --names {kind}{node} 2>/dev/null)'"
    return f"-f -a '{values}'"


FISH_FUNCTIONS = [
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
    "# __roc_positionals SPEC...: the positional words typed after the command (SPECs as above)",
    "function __roc_positionals",
    "    __roc_path >/dev/null",
    "    set -l words (commandline -opc)",
    "    set -l pending 0",
    "    for word in $words[$__roc_start..-1]",
    "        if string match -q -- '-*' $word",
    "            set pending 0",
    "            for spec in $argv",
    "                set -l parts (string split ':' -- $spec)",
    '                test "$parts[1]" = "$word"; and set pending $parts[2]',
    "            end",
    '        else if test "$pending" = "*"',
    "        else if test $pending -gt 0",
    "            set pending (math $pending - 1)",
    "        else",
    "            echo $word",
    "        end",
    "    end",
    "end",
    "# __roc_position COUNT MORE SPEC...: whether the current word is positional number COUNT (from 0),",
    "# or any from COUNT on when MORE is 1",
    "function __roc_position",
    "    __roc_value_of '*' $argv[3..-1]; and return 1",
    "    set -l given (count (__roc_positionals $argv[3..-1]))",
    '    test $given -eq $argv[1]; or begin; test "$argv[2]" = 1; and test $given -ge $argv[1]; end',
    "end",
]


def fish_script(tree: dict[tuple[str, ...], Command]) -> str:
    walk = []
    for path, command in sorted(tree.items()):
        for spelling, canonical in command.subcommands.items():
            target = _case_key(path + (canonical,))
            walk.append(f'            case "{_case_key(path)}|{spelling}"\n'
                        f'                set path "{target}"; set -g __roc_start (math $i + 1)')
    lines = [
        "# roc fish completion: roc completion fish > ~/.config/fish/completions/roc.fish",
        "function __roc_path",
        "    set -l path ''",
        "    set -g __roc_start 2",
        "    set -l words (commandline -opc)",
        "    for i in (seq 2 (count $words))",
        '        switch "$path|$words[$i]"',
        *walk,
        "        end",
        "    end",
        "    echo $path",
        "end",
        *FISH_FUNCTIONS,
        "complete -c roc -f",
    ]
    for path, command in sorted(tree.items()):
        condition = f"test (__roc_path) = '{_case_key(path)}'"
        specs = " ".join(f"'{option}:{count}'" for option, (count, _) in command.values.items())
        if command.subcommands:
            lines.append(f'complete -c roc -n "{condition}" -a "{" ".join(command.subcommands)}"')
        for index, (count, values) in enumerate(command.positionals):
            if values:
                more = 1 if count in ("*", "+") else 0
                lines.append(f'complete -c roc -n "{condition}; and __roc_position {index} {more} {specs}" '
                             f"{_fish_values(values, specs)}")
        for option in command.options:
            flag = f"-l {option[2:]}" if option.startswith("--") else f"-s {option[1:]}" if len(option) == 2 \
                else f"-o {option[1:]}"
            if option not in command.values:
                lines.append(f'complete -c roc -n "{condition}" {flag}')
                continue
            count, values = command.values[option]
            lines.append(f'complete -c roc -n "{condition}" {flag} -r {_fish_values(values, specs)}')
            if count != "1":  # the second and later values of a list option
                lines.append(f'complete -c roc -n "{condition}; and __roc_value_of {option} {specs}" '
                             f"{_fish_values(values, specs)}")
    return "\n".join(lines) + "\n"


def run(args: argparse.Namespace) -> int:
    if args.names:
        from roc.commands.completion_names import offered

        sys.stdout.write("".join(f"{name}\n" for name in offered(args.names, args.node)))
        return 0
    if args.shell is None:
        raise UsageError("give a shell (bash, zsh or fish), or --names KIND")
    from roc.cli.commands import build_parser

    tree = command_tree(build_parser())
    script = {"bash": bash_script, "zsh": zsh_script, "fish": fish_script}[args.shell](tree)
    sys.stdout.write(script)
    return 0
