"""Workspace configuration: ``roc.toml``, and colcon's ``defaults.yaml`` files for existing workspaces.

Values become argparse defaults, so the command line always wins. Precedence, highest first:
``[profile.NAME.VERB]`` and ``[profile.NAME]`` (with ``--profile NAME``), ``[VERB]``, ``[defaults]`` of
``roc.toml``; ``colcon_defaults.yaml`` in the workspace root; ``$COLCON_DEFAULTS_FILE`` (else
``~/.colcon/defaults.yaml``). ``[package.NAME]`` holds per-package settings (``cmake-args``,
``ament-cmake-args``, ``skip``); the ``names`` sections of colcon's metadata files (``colcon.meta``,
``--metas``, ``~/.colcon/metadata/*.meta``) are read for the same.

    [defaults]              # every verb
    base-paths = ["src"]
    [build]                 # roc work build
    parallel-workers = 4
    cmake-args = ["-DCMAKE_BUILD_TYPE=RelWithDebInfo"]
    [profile.release.build]
    cmake-args = ["-DCMAKE_BUILD_TYPE=Release"]
    [package.my_driver]
    cmake-args = ["-DWITH_FOO=ON"]
"""

from __future__ import annotations

import argparse
import os
import re
from pathlib import Path

from roc.errors import UsageError
from roc.messages import did_you_mean, unknown_package

TYPE_CHECKING = False  # typing is not imported at run time (start-up time of every verb)
if TYPE_CHECKING:
    from typing import Any

VERBS = ("list", "info", "graph", "build", "test", "env", "cache", "create")
PACKAGE_KEYS = {"cmake-args": list, "ament-cmake-args": list, "skip": bool}
ROC_TOML = "roc.toml"
# Options naming a directory: a relative value in roc.toml or colcon_defaults.yaml is taken from that
# file's directory (--base-paths and --paths too: discovery then starts from there, see load.resolve_root).
DIRECTORY_OPTIONS = ("build_base", "install_base", "log_base", "test_result_base")


class ConfigError(UsageError):
    def __init__(self, path: Path, key: str, message: str, line: int | None = None):
        where = f"{path}:{line}" if line else str(path)
        super().__init__(f"{where}: '{key}': {message}")


def _line_of(text: str, table: str, key: str) -> int | None:
    """The line of ``key`` inside ``[table]`` (tomllib does not say where a value came from)."""
    in_table = table == ""
    for number, line in enumerate(text.splitlines(), 1):
        stripped = line.strip()
        if stripped.startswith("["):
            in_table = stripped.strip("[] ").replace('"', "") == table
        elif in_table and re.match(rf'\s*"?{re.escape(key)}"?\s*=', line):
            return number
    return None


def header_lines(text: str, name: str) -> list[int]:
    """The lines of every ``[name]`` or ``[[name]]`` header (a dotted name, parts maybe quoted), in order."""
    dotted = r"\s*\.\s*".join(rf'"?{re.escape(part)}"?' for part in name.split("."))
    pattern = re.compile(rf"^\s*\[\[?\s*{dotted}\s*\]")
    return [number for number, line in enumerate(text.splitlines(), 1) if pattern.match(line)]


def key_line(text: str, start: int, key: str) -> int:
    """The line of ``key`` in the table whose header is on line ``start`` (the header's line if absent)."""
    lines = text.splitlines()
    for number in range(start + 1, len(lines) + 1):
        line = lines[number - 1]
        if line.lstrip().startswith("["):
            break
        if re.match(rf'\s*"?{re.escape(key)}"?\s*=', line):
            return number
    return start


def _value_tokens(text: str, line: int):
    """(line, character) of each character of the value of the key on line ``line`` and of what follows it,
    without spaces and comments, each string as one ``"``."""
    quote = ""
    for number, content in enumerate(text.splitlines()[line - 1:], line):
        column = content.find("=") + 1 if number == line else 0
        while column < len(content):
            if quote:
                if quote[0] == '"' and content[column] == "\\":
                    column += 2
                elif content.startswith(quote, column):
                    column, quote = column + len(quote), ""
                else:
                    column += 1
                continue
            char = content[column]
            if char == "#":
                break
            if char in "\"'":
                quote = char * 3 if content.startswith(char * 3, column) else char
                column += len(quote)
                yield number, '"'
                continue
            if not char.isspace():
                yield number, char
            column += 1


def array_item_lines(text: str, line: int) -> list[int]:
    """The line of each item of the array that is the value of the key on line ``line`` (``nodes = [...]``,
    ``topic = [{...}, {...}]``; TOML's inline tables never span lines)."""
    found: list[int] = []
    depth, expecting = 0, False
    for number, char in _value_tokens(text, line):
        if depth == 1 and expecting and char not in ",]":
            found.append(number)
            expecting = False
        if char in "[{":
            depth += 1
            expecting = expecting or depth == 1
        elif char in "]}":
            depth -= 1
            if depth <= 0:
                break
        elif char == "," and depth == 1:
            expecting = True
    return found


def type_names(types: tuple[type, ...]) -> str:
    """``a string``, ``an integer or a number``: what a value of ``types`` is, for messages."""
    names = {bool: "true or false", int: "an integer", float: "a number", str: "a string", list: "a list",
             dict: "a table"}
    return " or ".join(dict.fromkeys(names[t] for t in types))


def check_table(path: Path, text: str, start: int, table: dict, schema: dict[str, tuple[tuple[type, ...], bool]],
                where: str) -> None:
    """Every key of ``table`` (whose header is on line ``start`` of ``text``) is in ``schema`` ({key:
    (accepted types, required)}) with a value of its types, and every required key is there; else a
    ConfigError naming the file, the line and the key. ``where`` names the table, e.g. ``[[check.topic]]``."""
    for key, value in table.items():
        line = key_line(text, start, key)
        if key not in schema:
            hint = _closest(key, schema)
            raise ConfigError(path, key, f"unknown key of {where}; {hint}use {', '.join(schema)}", line)
        types, _ = schema[key]
        if not isinstance(value, types) or (isinstance(value, bool) and bool not in types):
            raise ConfigError(path, key, f"expected {type_names(types)}, got {value!r}", line)
    for key, (_, required) in schema.items():
        if required and key not in table:
            raise ConfigError(path, key, f"missing in {where}", start)


class Setting:
    """One configured value and where it came from."""

    def __init__(self, value, source: str, path: Path, table: str, key: str, line: int | None):
        self.value, self.source, self.path, self.table, self.key, self.line = value, source, path, table, key, line


class Configuration:
    def __init__(self, root: Path | None = None) -> None:
        self.root = root  # the workspace root, where roc.toml and colcon_defaults.yaml are
        self.layers: list[dict[str, Setting]] = []  # lowest precedence first
        self.packages: dict[str, dict[str, Setting]] = {}
        self.applied: dict[str, object] = {}  # argparse dest -> the default it was given
        self.package_tables: dict[str, tuple[Path, int | None]] = {}  # roc.toml's [package.NAME] lines

    def from_configuration(self, args: argparse.Namespace, dest: str) -> bool:
        """Whether ``args.<dest>`` is the configured value (not given on the command line)."""
        return dest in self.applied and getattr(args, dest, None) is self.applied[dest]

    def add_layer(self, values: dict, source: str, path: Path, table: str, text: str | None) -> None:
        layer = {}
        for key, value in values.items():
            line = _line_of(text, table, key) if text is not None else None
            layer[key] = Setting(value, source, path, table, key, line)
        self.layers.append(layer)

    def package_values(self, key: str) -> dict[str, object]:
        """``key`` of every package that sets it, e.g. {"my_driver": ["-DWITH_FOO=ON"]}."""
        return {name: settings[key].value for name, settings in self.packages.items() if key in settings}

    def effective(self) -> dict[str, Setting]:
        merged: dict[str, Setting] = {}
        for layer in self.layers:
            merged.update(layer)
        return merged


def _closest(word: str, candidates) -> str:
    """``did you mean 'X'? `` for the closest of ``candidates``, else nothing."""
    hint = did_you_mean(word, candidates, count=1)
    return f"{hint} " if hint else ""


def check_package_tables(config: Configuration, names: set[str]) -> None:
    """Every ``[package.NAME]`` of roc.toml names a package of the workspace (a misspelled table would
    otherwise be ignored without a word)."""
    for name, (path, line) in config.package_tables.items():
        if name not in names:
            raise ConfigError(path, f"[package.{name}]", unknown_package(name, names), line)


def _dest(key: str) -> str:
    return key.replace("-", "_")


def _check_type(setting: Setting, action: argparse.Action):
    """The value converted for ``action``, or a ConfigError that says what is expected."""
    value = setting.value
    expected: str
    if isinstance(action, (argparse._StoreTrueAction, argparse._StoreFalseAction)):
        if isinstance(value, bool):
            return value
        expected = "true or false"
    elif action.nargs in ("*", "+") or isinstance(action, argparse._AppendAction):
        if isinstance(value, list) and all(isinstance(v, (str, int, float)) for v in value):
            converted = [str(v) for v in value]
            if action.nargs == "+" and not converted:
                expected = "a non-empty list"
            else:
                return converted
        else:
            expected = "a list of strings"
    elif action.type is int:
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        expected = "a whole number"
    elif isinstance(value, str):
        if action.choices and value not in action.choices:
            expected = f"one of {', '.join(map(str, action.choices))}"
        else:
            return value
    else:
        expected = "a string"
    raise ConfigError(setting.path, setting.key, f"must be {expected}, not {value!r}", setting.line)


def colcon_home() -> Path:
    return Path(os.environ.get("COLCON_HOME") or os.path.join(os.path.expanduser("~"), ".colcon"))


def meta_files(root: Path, metas: list[str] | None, ignore_user_meta: bool) -> list[Path]:
    """colcon's metadata files, lowest precedence first: ``~/.colcon/metadata/*.meta`` (unless
    ignored), then ``--metas`` (files, or directories holding a colcon.meta; default ./colcon.meta)."""
    files = [] if ignore_user_meta else sorted((colcon_home() / "metadata").glob("*.meta"))
    for given in metas if metas is not None else ["colcon.meta"]:
        path = root / given
        files.append(path / "colcon.meta" if path.is_dir() else path)
    return files


def load_configuration(root: Path, verb: str, profile: str | None, metas: list[str] | None = None,
                       ignore_user_meta: bool = False) -> Configuration:
    config = Configuration(root)
    _load_colcon_defaults(config, root, verb)
    for path in meta_files(root, metas, ignore_user_meta):
        _load_colcon_meta(config, path)
    toml_path = root / ROC_TOML
    if toml_path.is_file():
        _load_roc_toml(config, toml_path, verb, profile)
    elif profile:
        raise UsageError(f"--profile {profile}: there is no {toml_path}")
    return config


def _load_colcon_defaults(config: Configuration, root: Path, verb: str) -> None:
    files = []
    user = os.environ.get("COLCON_DEFAULTS_FILE") or str(colcon_home() / "defaults.yaml")
    files.append(Path(user))
    files.append(root / "colcon_defaults.yaml")
    for path in files:
        if not path.is_file():
            continue
        import yaml

        try:
            data = yaml.safe_load(path.read_text()) or {}
        except yaml.YAMLError as error:
            line = getattr(getattr(error, "problem_mark", None), "line", None)
            raise ConfigError(path, verb, f"invalid YAML: {getattr(error, 'problem', error)}",
                              line + 1 if line is not None else None) from None
        if not isinstance(data, dict):
            raise ConfigError(path, "(top level)", "must map verb names to their options")
        section = data.get(verb) or {}
        if not isinstance(section, dict):
            raise ConfigError(path, verb, "must map option names to values")
        config.add_layer(section, f"{path.name} [{verb}]", path, verb, None)


def _check_package_setting(setting: Setting) -> None:
    expected = PACKAGE_KEYS[setting.key]
    value: Any = setting.value
    if not isinstance(value, expected) or (isinstance(value, list) and not all(isinstance(v, str) for v in value)):
        kind = "a list of strings" if expected is list else "true or false"
        raise ConfigError(setting.path, setting.key, f"must be {kind}, not {value!r}", setting.line)


def _load_colcon_meta(config: Configuration, path: Path) -> None:
    """colcon.meta's ``names`` section: per-package arguments (roc.toml's [package.NAME] wins)."""
    if not path.is_file():
        return
    import yaml

    from roc.messages import warn

    try:
        data = yaml.safe_load(path.read_text()) or {}
    except yaml.YAMLError as error:
        raise ConfigError(path, "(syntax)", f"invalid YAML: {getattr(error, 'problem', error)}") from None
    names = data.get("names") if isinstance(data, dict) else None
    if not isinstance(names or {}, dict):
        raise ConfigError(path, "names", "must map package names to their settings")
    for name, settings in (names or {}).items():
        if not isinstance(settings or {}, dict):
            raise ConfigError(path, str(name), "must map settings such as cmake-args to values")
        for key, value in (settings or {}).items():
            if key not in PACKAGE_KEYS:
                warn(f"{path}: '{key}' of package '{name}' is not used by roc (it uses {', '.join(PACKAGE_KEYS)})")
                continue
            setting = Setting(value, path.name, path, str(name), key, None)
            _check_package_setting(setting)
            config.packages.setdefault(str(name), {})[key] = setting


def _load_roc_toml(config: Configuration, path: Path, verb: str, profile: str | None) -> None:
    import tomllib

    text = path.read_text()
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        match = re.search(r"(.*) \(at line (\d+), column (\d+)\)", str(error))
        if match:
            raise UsageError(f"{path}:{match[2]}:{match[3]}: invalid TOML: {match[1]}") from None
        if "at end of document" in str(error):
            lines = text.splitlines() or [""]
            raise UsageError(f"{path}:{len(lines)}:{len(lines[-1]) + 1}: invalid TOML: "
                             f"{str(error).split(' (at ')[0]} (at the end of the file)") from None
        raise UsageError(f"{path}: invalid TOML: {error}") from None
    # [check]: roc.check.expectations; [launch.NAME]: roc.launch.system
    known_tables = {"defaults", "profile", "package", "check", "launch", *VERBS}
    for table, values in data.items():
        if table not in known_tables or not isinstance(values, dict):
            raise ConfigError(path, table, f"unknown table; {_closest(table, known_tables)}use [defaults], "
                                           f"[{'], ['.join(VERBS)}], [profile.NAME], [package.NAME], [check], "
                                           "[launch.NAME]", _line_of(text, table, table) or
                              next((n for n, line in enumerate(text.splitlines(), 1) if f"[{table}" in line), None))
    config.add_layer(data.get("defaults", {}), f"{ROC_TOML} [defaults]", path, "defaults", text)
    config.add_layer(data.get(verb, {}), f"{ROC_TOML} [{verb}]", path, verb, text)
    for table in ("package", "profile"):
        for name, value in data.get(table, {}).items():
            if not isinstance(value, dict):
                raise ConfigError(path, f"{table}.{name}", f"must be a table: [{table}.{name}]",
                                  _line_of(text, table, name))
    if profile:
        profiles = data.get("profile", {})
        if profile not in profiles:
            available = ", ".join(sorted(profiles)) or "none"
            raise UsageError(f"--profile {profile}: {path} has no [profile.{profile}] (profiles: {available})")
        chosen = profiles[profile]
        shared = {k: v for k, v in chosen.items() if k not in VERBS}
        config.add_layer(shared, f"{ROC_TOML} [profile.{profile}]", path, f"profile.{profile}", text)
        if not isinstance(chosen.get(verb, {}), dict):
            raise ConfigError(path, f"profile.{profile}.{verb}", f"must be a table: [profile.{profile}.{verb}]",
                              _line_of(text, f"profile.{profile}", verb))
        config.add_layer(chosen.get(verb, {}), f"{ROC_TOML} [profile.{profile}.{verb}]", path,
                         f"profile.{profile}.{verb}", text)
    for name, settings in data.get("package", {}).items():
        table = f"package.{name}"
        config.package_tables[name] = (path, next((n for n, line in enumerate(text.splitlines(), 1)
                                                   if line.strip().replace('"', "").replace(" ", "")
                                                   .startswith(f"[{table}]")), None))
        package = config.packages.setdefault(name, {})
        for key, value in settings.items():
            setting = Setting(value, f"{ROC_TOML} [{table}]", path, table, key, _line_of(text, table, key))
            if key not in PACKAGE_KEYS:
                raise ConfigError(path, key, f"unknown package setting; {_closest(key, PACKAGE_KEYS)}"
                                             f"use {', '.join(PACKAGE_KEYS)}", setting.line)
            _check_package_setting(setting)
            package[key] = setting


def apply_configuration(parser: argparse.ArgumentParser, config: Configuration) -> dict[str, Setting]:
    """Validate every configured option against ``parser`` and make it a default; returns them."""
    actions = {a.dest: a for a in parser._actions if a.option_strings}
    applied: dict[str, Setting] = {}
    for key, setting in config.effective().items():
        action = actions.get(_dest(key))
        if action is None or action.dest in ("help", "profile"):
            options = sorted(o[2:] for a in actions.values() for o in a.option_strings
                             if o.startswith("--") and o not in ("--help", "--profile"))
            raise ConfigError(setting.path, key, f"not an option of this verb; {_closest(key, options)}"
                              f"options: {' '.join(options)}", setting.line)
        applied[action.dest] = setting
        value = _check_type(setting, action)
        if action.dest in DIRECTORY_OPTIONS and setting.path.parent == config.root:
            value = str(setting.path.parent / value)  # relative to roc.toml's directory, wherever roc runs
        config.applied[action.dest] = value
        parser.set_defaults(**{action.dest: value})
    return applied
