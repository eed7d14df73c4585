"""The TUI page's tables of keys and palette commands, generated at build time from the app's own
bindings (roc.tui.keys), in place of the ``<!-- tui-keys -->`` and ``<!-- tui-commands -->`` markers."""

from __future__ import annotations


def on_page_markdown(markdown: str, page, config, files) -> str:
    if "<!-- tui-keys -->" not in markdown and "<!-- tui-commands -->" not in markdown:
        return markdown
    from roc.tui.keys import command_table, key_table

    return markdown.replace("<!-- tui-keys -->", key_table()).replace("<!-- tui-commands -->", command_table())
