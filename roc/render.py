"""Everything a verb prints to stdout goes through here: lines of text, aligned tables, JSON and YAML.

Verbs build plain data (lists, dicts) and pick a renderer by ``--format``; nothing else writes
``json.dumps``/``yaml.dump`` output or pads columns by hand, so every verb's formats look alike.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable, Sequence
from functools import lru_cache

TYPE_CHECKING = False  # typing and json are not imported by a command that does not need them (start-up time)
if TYPE_CHECKING:
    from typing import Any, TextIO


def plural(count: int, word: str) -> str:
    """``1 topic``, ``3 topics``."""
    return f"{count} {word}{'' if count == 1 else 's'}"


def print_lines(lines: Iterable[str], stream: TextIO | None = None) -> None:
    (stream or sys.stdout).write("".join(f"{line}\n" for line in lines))


def print_text(text: str, stream: TextIO | None = None) -> None:
    """Text as it is, flushed (for streams: each message as it arrives, also through a pipe)."""
    out = stream or sys.stdout
    out.write(text)
    out.flush()


def print_events(events: Iterable[dict[str, Any]], fmt: str, text: Callable[[dict[str, Any]], str]) -> None:
    """Status events as they come (``roc bridge``): JSON lines, or each event's ``text`` (may be empty)."""
    for event in events:
        print_text(json_line(event) if fmt == "json" else text(event))


def print_json(data: Any, stream: TextIO | None = None) -> None:
    """One JSON document, indented (for listings)."""
    import json

    out = stream or sys.stdout
    json.dump(data, out, indent=2, sort_keys=False)
    out.write("\n")


def json_line(data: Any) -> str:
    """One compact JSON object and a newline."""
    import json

    return json.dumps(data, separators=(",", ":")) + "\n"


def print_json_line(data: Any, stream: TextIO | None = None) -> None:
    """One compact JSON object on one line, flushed (for streams: events, messages, status)."""
    print_text(json_line(data), stream)


def to_yaml(data: Any, flow_style: bool | None = False) -> str:
    """YAML with keys in their given order, as ros2 prints messages and parameters."""
    import yaml

    return yaml.dump(data, sort_keys=False, default_flow_style=flow_style, allow_unicode=True)


def to_yaml_line(data: Any) -> str:
    """Data as one line of YAML in flow style (``{success: true, message: ''}``, ``1.5``, ``[1, 2]``), for
    a value inside a line of text."""
    import yaml

    text = yaml.dump(data, sort_keys=False, default_flow_style=True, allow_unicode=True, width=2**31 - 1)
    return text.removesuffix("\n").removesuffix("\n...").strip()


@lru_cache(maxsize=2)
def _message_dumper(fast: bool) -> type:
    """A yaml Dumper (libyaml's when ``fast``) whose mappings never take the flow style, as
    rosidl_runtime_py's OrderedDict representer does."""
    import yaml

    class MessageDumper(yaml.CDumper if fast else yaml.Dumper):  # type: ignore[misc]
        pass

    def block_mapping(dumper: yaml.Dumper, mapping: dict) -> yaml.MappingNode:
        items = [(dumper.represent_data(k), dumper.represent_data(v)) for k, v in mapping.items()]
        return yaml.MappingNode("tag:yaml.org,2002:map", items)

    MessageDumper.add_representer(dict, block_mapping)
    return MessageDumper


def to_message_yaml(data: Any, flow_style: bool = False) -> str:
    """YAML as ``ros2 topic echo`` prints a message: keys in order, no line wrapping and, with
    ``flow_style`` (``--flow-style``), lists inline but mappings still in block style.

    libyaml writes the same text 3-4 times faster, except that it escapes characters beyond the
    BMP (``\\U0001F600``) where PyYAML writes them as they are: such text is redone with PyYAML."""
    import yaml

    def dump(fast: bool) -> str:
        return yaml.dump(data, Dumper=_message_dumper(fast), default_flow_style=flow_style, allow_unicode=True,
                         width=2**31 - 1)  # never wrap (libyaml takes a C int)

    fast = getattr(yaml, "__with_libyaml__", False)
    text = dump(fast)
    return dump(False) if fast and "\\U" in text else text


def print_yaml(data: Any, stream: TextIO | None = None) -> None:
    (stream or sys.stdout).write(to_yaml(data))


def table_lines(rows: Sequence[Sequence[Any]], header: Sequence[str] | None = None, gap: str = "  ") -> list[str]:
    """Rows as left-aligned columns (the last column is not padded)."""
    all_rows = [list(map(str, header))] if header else []
    all_rows += [[str(cell) for cell in row] for row in rows]
    if not all_rows:
        return []
    widths = [max(len(row[i]) for row in all_rows if i < len(row)) for i in range(max(map(len, all_rows)))]
    return [gap.join(cell.ljust(widths[i]) if i < len(row) - 1 else cell for i, cell in enumerate(row)).rstrip()
            for row in all_rows]


def print_table(rows: Sequence[Sequence[Any]], header: Sequence[str] | None = None, gap: str = "  ") -> None:
    print_lines(table_lines(rows, header, gap))


def render(data: Any, output_format: str, text: Iterable[str] | None = None) -> None:
    """Print ``data`` as ``json`` or ``yaml``; as ``text``, the given lines."""
    if output_format == "json":
        print_json(data)
    elif output_format == "yaml":
        print_yaml(data)
    else:
        print_lines(text if text is not None else [str(data)])
