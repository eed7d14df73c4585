"""``roc tui``'s application: the screens on a stack (Enter opens, Esc goes back), the keys every
screen has (``q`` quits, ``?`` lists every key, ``:`` the command palette), and the build that runs
while the TUI shows it."""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import TYPE_CHECKING

from textual.app import App
from textual.binding import Binding
from textual.screen import Screen

from roc.errors import RocError, UsageError
from roc.tui.feed import Feed
from roc.tui.graph_screen import GraphScreen
from roc.tui.keys import MOVES
from roc.tui.packages import WorkspaceView
from roc.tui.palette import RocCommands, palette_lines
from roc.tui.widgets import TextViewer, binding_lines

if TYPE_CHECKING:  # builds load the engine's modules only when one starts
    from textual.await_complete import AwaitComplete

    from roc.tui.build_run import BuildRun, Start


VIEW_USAGE = {"array": "array TOPIC FIELD: e.g. array /scan ranges", "scan": "scan TOPIC: e.g. scan /scan",
              "grid": "grid TOPIC: e.g. grid /map"}


class RocApp(App[int]):
    TITLE = "roc tui"
    BINDINGS = [
        Binding("q", "quit", "quit"),
        Binding("question_mark", "help", "help"),
        Binding("colon,ctrl+p", "command_palette", "commands"),
        Binding("right_square_bracket", "forward", "forward again to the screen Esc left", show=False),
    ]
    COMMANDS = {RocCommands}

    def __init__(self, feed: Feed | None = None, workspace: WorkspaceView | None = None,
                 build: Start | None = None, new_build: Callable[[list[str]], Start] | None = None,
                 checks=None, bag: str | None = None) -> None:
        """``build``: show this build at once (``roc work build --tui``) instead of the graph;
        ``new_build``: how to build packages of the workspace from the TUI; ``checks``: roc.toml's
        ``[check]`` expectations (roc.check.expectations.CheckFile) the problems line holds the graph
        to; ``bag``: a bag to open at once. With NO_COLOR set, no
        colour at all (Textual alone would draw in greys), styles such as bold and reverse kept."""
        super().__init__(ansi_color=True if os.environ.get("NO_COLOR") else None)
        self.new_build = new_build
        self.feed = feed or Feed()
        self.workspace = workspace
        self.graph_screen: GraphScreen | None = None
        self.build: BuildRun | None = None
        self._first_build = build
        self.checks = checks
        self.bag = bag
        self._forward: list[tuple[str, str]] = []  # (kind, name) of the screens Esc left, the last on top
        from roc.tui.diagnostics_screen import Diagnostics
        from roc.tui.logs_screen import Logs

        self.diagnostics = Diagnostics()  # /diagnostics's statuses, kept while the TUI runs
        self.logs = Logs()  # /rosout, kept while the TUI runs

    def on_mount(self) -> None:
        if self._first_build is not None:
            from roc.tui.build_run import BuildRun
            from roc.tui.build_screen import BuildScreen

            self.build = BuildRun(self._first_build)
            self.push_screen(BuildScreen(self.build))
        else:
            self.graph_screen = GraphScreen(self.workspace, self.checks)
            self.push_screen(self.graph_screen)
            if self.bag:
                self.open("bag", self.bag)

    def open(self, kind: str, name: str = "", forward: bool = False) -> None:
        """Push the screen of a node, topic, service or action (``name``), or a view of the palette
        (roc.tui.palette.VIEWS: ``name`` holds its words). Opening one forgets the screens Esc left,
        as a browser does, unless it is one of them (``forward``)."""
        from roc.tui import call_screens

        screen: Screen | None = None
        if kind in ("nodes", "topics", "services", "actions"):
            if self.graph_screen is not None:
                while self.screen is not self.graph_screen and len(self.screen_stack) > 1:
                    self.pop_screen()
                self.graph_screen.action_show_tab(kind)
        elif kind == "build":
            self.start_build([])
        elif kind in ("service", "action"):
            call = call_screens.ServiceScreen if kind == "service" else call_screens.ActionScreen
            screen = call(name, self.type_of(kind, name))
        elif kind == "publish":
            screen = call_screens.PublishScreen(name, self.type_of("topic", name))
        else:
            try:
                screen = self.view(kind, name)
            except RocError as error:
                self.notify(str(error), severity="error")
        if not forward:
            self._forward.clear()
        if screen is not None:
            screen.reopen = (kind, name)  # type: ignore[attr-defined]
            self.push_screen(screen)

    def pop_screen(self) -> AwaitComplete:
        """Back (Esc): the screen left can be opened again with ``]``."""
        reopen = getattr(self.screen, "reopen", None)
        done = super().pop_screen()
        if reopen is not None:
            self._forward.append(reopen)
        return done

    def action_forward(self) -> None:
        if self._forward:
            self.open(*self._forward.pop(), forward=True)

    def view(self, kind: str, name: str):
        """The screen of a node or topic, or of a view that takes words (or none)."""
        if kind == "node":
            from roc.tui.node_screen import NodeScreen

            return NodeScreen(name)
        if kind == "topic":
            from roc.tui.topic_screen import TopicScreen

            return TopicScreen(name)
        if kind in ("frame", "frames"):
            from roc.tui.frames_screen import FramesScreen

            return FramesScreen()
        if kind == "logs":
            from roc.tui.logs_screen import LogsScreen

            return LogsScreen(node=name)
        if kind == "diagnostics":
            from roc.tui.diagnostics_screen import DiagnosticsScreen

            return DiagnosticsScreen()
        if kind == "plot":
            from roc.tui.plot_screen import PlotScreen

            words = name.split()
            if len(words) < 2:
                raise UsageError("plot TOPIC FIELD [FIELD...]: e.g. plot /odom pose.pose.position.x")
            return PlotScreen([(words[0], field) for field in words[1:]])
        if kind == "bag":
            from roc.tui.bag_screen import BagScreen

            return BagScreen(name)
        if kind == "launch":
            from roc.tui.launch_screen import LaunchScreen

            return LaunchScreen()
        if kind in ("array", "scan", "grid"):
            from roc.tui.image_screen import SensorScreen

            words = name.split()
            if len(words) != (2 if kind == "array" else 1):
                raise UsageError(VIEW_USAGE[kind])
            return SensorScreen(kind, *words)
        if kind == "image":
            from roc.tui.image_screen import ImageScreen

            if not name:
                raise UsageError("image TOPIC: e.g. image /camera/image_raw")
            return ImageScreen(name, self.type_of("topic", name))
        raise UsageError(f"no view '{kind}'")

    def type_of(self, kind: str, name: str) -> str:
        """A topic's, service's or action's type from the last snapshot ("" when unknown)."""
        snapshot = self.graph_screen.snapshot if self.graph_screen else None
        entry = next((e for e in (snapshot or {}).get(f"{kind}s", []) if e["name"] == name), None)
        return entry["types"][0] if entry and entry["types"] else ""

    def open_package(self, name: str) -> None:
        if self.workspace is not None:
            self.push_screen(TextViewer(f"package {name}", self.workspace.details(name)))

    def start_build(self, packages: list[str]) -> None:
        """Build ``packages`` (all when empty) of the workspace and show it; one build at a time."""
        from roc.tui.build_run import BuildRun
        from roc.tui.build_screen import BuildScreen

        if self.new_build is None:
            return
        if self.build is not None and self.build.running():
            self.notify("a build is running", severity="warning")
        else:
            try:
                self.build = BuildRun(self.new_build(packages))
            except RocError as error:
                self.notify(str(error), severity="error")
                return
        self.push_screen(BuildScreen(self.build))

    def action_help(self) -> None:
        screen = type(self.screen).__name__.removesuffix("Screen")
        lines = binding_lines(f"{screen} screen", self.screen.BINDINGS, self.get_key_display)
        lines += binding_lines("everywhere", self.BINDINGS, self.get_key_display)
        lines += [f"{keys}: {what}" for keys, what in MOVES]
        lines += ["Enter opens what is under the cursor; Esc goes back (or clears the filter).",
                  "In an input: Enter accepts, Esc cancels.", "",
                  "commands (: opens the palette, then type one):", *(f"  {line}" for line in palette_lines())]
        self.push_screen(TextViewer("keys (Esc: back)", "\n".join(lines)))

    async def action_quit(self) -> None:
        """Quit; a running build is stopped first (its process trees with it)."""
        if self.build is not None and self.build.running():
            self.notify("stopping the build...")
            self.build.stop.set()
            await self.run_in_thread(self.build.finish)
        shown_build = self._first_build is not None and self.build is not None  # roc work build --tui
        self.exit(self.build.code or 0 if shown_build and self.build else 0)

    async def run_in_thread(self, function) -> None:
        import asyncio

        await asyncio.get_running_loop().run_in_executor(None, function)


def run_build_app(start: Start, verb: str = "build") -> int:
    """``roc work build --tui``: the build shown live; once the user quits, the console's summary
    is printed and the build's exit code returned (a build still running is stopped first)."""
    import io

    from roc.handlers.console import ConsoleHandler
    from roc.render import print_text

    summary = io.StringIO()
    console = ConsoleHandler(summary, start_end=False, stderr=False, kind=verb)
    app = RocApp(build=lambda handlers, stop: start([*handlers, console], stop))
    try:
        app.run()
    finally:
        code = app.build.finish() if app.build is not None else 1
    print_text(summary.getvalue().lstrip("\n"))
    if app.build is not None and app.build.error:
        raise RocError(app.build.error)
    return code
