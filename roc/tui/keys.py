"""Every key of ``roc tui`` and every command of its palette, from the screens' own bindings
(roc.tui.palette for the commands): the manual's table (docs/hooks/tui_keys.py) and the tests read them
here, so that they are never written twice."""

from __future__ import annotations

from textual.binding import Binding

# (screen, its class's module and name), in the order the manual lists them
SCREENS = (
    ("everywhere", "roc.tui.app", "RocApp"),
    ("first screen", "roc.tui.graph_screen", "GraphScreen"),
    ("node", "roc.tui.node_screen", "NodeScreen"),
    ("topic", "roc.tui.topic_screen", "TopicScreen"),
    ("logs", "roc.tui.logs_screen", "LogsScreen"),
    ("plot", "roc.tui.plot_screen", "PlotScreen"),
    ("image", "roc.tui.image_screen", "ImageScreen"),
    ("array, scan, grid", "roc.tui.image_screen", "SensorScreen"),
    ("diagnostics", "roc.tui.diagnostics_screen", "DiagnosticsScreen"),
    ("service, action", "roc.tui.call_screens", "ActionScreen"),
    ("publish", "roc.tui.call_screens", "PublishScreen"),
    ("bag", "roc.tui.bag_screen", "BagScreen"),
    ("launch", "roc.tui.launch_screen", "LaunchScreen"),
    ("tf frames", "roc.tui.frames_screen", "FramesScreen"),
    ("build", "roc.tui.build_screen", "BuildScreen"),
)
# Textual's key names as the manual writes them
NAMES = {"slash": "/", "question_mark": "?", "colon": ":", "escape": "Esc", "enter": "Enter", "tab": "Tab",
         "shift+tab": "Shift+Tab", "space": "Space", "plus": "+", "equals_sign": "=", "minus": "-",
         "full_stop": ".", "greater_than_sign": ">", "less_than_sign": "<",
         "right_square_bracket": "]"}


# the keys of every list (roc.tui.widgets.ListTable), as the manual and the help say them
MOVES = (("Up/Down, Page Up/Down, Home/End", "move in a list (Home, End: to its first, its last row)"),
         ("Left/Right", "scroll a list wider than the screen sideways"))


def key_text(key: str) -> str:
    if key in NAMES:
        return f"`{NAMES[key]}`" if len(NAMES[key]) == 1 else NAMES[key]
    if key.startswith("ctrl+"):
        return f"Ctrl+{key[5:].upper()}"
    return f"`{key}`"


def bindings() -> list[tuple[str, str, str]]:
    """(screen, keys, what it does) of every binding with a description."""
    import importlib

    found = []
    for screen, module, name in SCREENS:
        for binding in getattr(importlib.import_module(module), name).BINDINGS:
            if isinstance(binding, Binding) and binding.description:
                keys = ", ".join(key_text(key.strip()) for key in binding.key.split(","))
                found.append((screen, keys, binding.description))
    return found


def key_table() -> str:
    """The manual's table of keys (Markdown)."""
    lines = ["| screen | key | what it does |", "| --- | --- | --- |"]
    lines += [f"| {screen} | {keys} | {what} |" for screen, keys, what in bindings()]
    lines += [f"| everywhere | {keys} | {what} |" for keys, what in MOVES]
    lines.append("| prompts and text | Enter, Esc | accept, cancel (close) |")
    return "\n".join(lines)


def command_table() -> str:
    """The manual's table of palette commands (Markdown)."""
    from roc.tui.palette import VIEWS

    lines = ["| command | what it opens |", "| --- | --- |"]
    lines += [f"| `:{name}{' ' + words if words else ''}` | {what} |" for name, (words, what) in VIEWS.items()]
    lines.append("| `:node NAME`, `:topic NAME`, `:service NAME`, `:action NAME` "
                 "| that node, topic, service or action |")
    return "\n".join(lines)
