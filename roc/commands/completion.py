"""``roc completion SHELL``: a completion script made from roc's own argument parser.

Commands and options complete from the parser; options taking package names complete from
``roc work list -n`` in the current workspace.
"""

from __future__ import annotations

import argparse
import sys

PACKAGE_METAVARS = {"PKG_NAME", "DEP_NAME"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("shell", choices=("bash", "zsh", "fish"),
                        help="e.g. 'source <(roc completion bash)' in ~/.bashrc; "
                             "'roc completion fish > ~/.config/fish/completions/roc.fish'")


def command_tree(parser: argparse.ArgumentParser, path: tuple[str, ...] = ()) -> dict:
    """{path: (subcommands {spelling: canonical}, options, package-name options)} for every command."""
    subcommands: dict[str, str] = {}
    options: list[str] = []
    package_options: list[str] = []
    tree: dict = {}
    for action in parser._actions:  # argparse has no public API for walking its parsers
        if isinstance(action, argparse._SubParsersAction):
            canonical = {id(p): name for name, p in reversed(list(action.choices.items()))}
            for name, sub in action.choices.items():
                subcommands[name] = canonical[id(sub)]
                if canonical[id(sub)] == name:
                    tree.update(command_tree(sub, path + (name,)))
        elif action.option_strings:
            options += action.option_strings
            metavar = action.metavar if isinstance(action.metavar, tuple) else (action.metavar,)
            if PACKAGE_METAVARS & set(metavar):
                package_options += [o for o in action.option_strings if o.startswith("--")]
    tree[path] = (subcommands, options, package_options)
    return tree


def all_options(parser: argparse.ArgumentParser) -> set[str]:
    """Every option string of every command (not the global ones such as -C, which only go before it)."""
    return {option for path, (_, options, _) in command_tree(parser).items() if path for option in options}


def _case_key(path: tuple[str, ...]) -> str:
    return " ".join(path)


def bash_script(tree: dict) -> str:
    walk, cases = [], []
    for path, (subcommands, options, package_options) in sorted(tree.items()):
        for spelling, canonical in subcommands.items():
            walk.append(f'      "{_case_key(path)}|{spelling}") path="{_case_key(path + (canonical,))}" ;;')
        words = " ".join([*subcommands, *options])
        package_case = "|".join(package_options)
        cases.append(f'    "{_case_key(path)}")\n      words="{words}"'
                     + (f'\n      case "$prev" in {package_case}) package=1 ;; esac' if package_options else "")
                     + "\n      ;;")
    return f"""# roc bash completion: source <(roc completion bash)
_roc_complete() {{
  local cur="${{COMP_WORDS[COMP_CWORD]}}" prev="${{COMP_WORDS[COMP_CWORD-1]}}"
  local path="" words="" package=0 i
  for ((i = 1; i < COMP_CWORD; i++)); do
    case "$path|${{COMP_WORDS[i]}}" in
{chr(10).join(walk)}
    esac
  done
  case "$path" in
{chr(10).join(cases)}
  esac
  if [[ $package == 1 && $cur != -* ]]; then
    COMPREPLY=($(compgen -W "$(roc work list -n 2>/dev/null)" -- "$cur"))
  else
    COMPREPLY=($(compgen -W "$words" -- "$cur"))
  fi
}}
complete -F _roc_complete roc
"""


def zsh_script(tree: dict) -> str:
    return "# roc zsh completion: source <(roc completion zsh)\nautoload -U +X bashcompinit && bashcompinit\n" + bash_script(tree)


def fish_script(tree: dict) -> str:
    walk = []
    for path, (subcommands, _options, _package_options) in sorted(tree.items()):
        for spelling, canonical in subcommands.items():
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
        "complete -c roc -f",
    ]
    for path, (subcommands, options, package_options) in sorted(tree.items()):
        condition = f"test (__roc_path) = '{_case_key(path)}'"
        if subcommands:
            lines.append(f'complete -c roc -n "{condition}" -a "{" ".join(subcommands)}"')
        for option in options:
            flag = f"-l {option[2:]}" if option.startswith("--") else f"-s {option[1:]}"
            needs_package = option in package_options
            extra = " -x -a '(roc work list -n 2>/dev/null)'" if needs_package else ""
            lines.append(f'complete -c roc -n "{condition}" {flag}{extra}')
    return "\n".join(lines) + "\n"


def run(args: argparse.Namespace) -> int:
    from roc.cli.commands import build_parser

    tree = command_tree(build_parser())
    script = {"bash": bash_script, "zsh": zsh_script, "fish": fish_script}[args.shell](tree)
    sys.stdout.write(script)
    return 0
