"""roc tui on a middleware that gives no publication sequence numbers (Cyclone DDS): the topic screen's
and the plot's lost-message counts read "unknown", never 0."""

from __future__ import annotations

from roc.ros.rates import Sample, Window
from roc.tui.topic_screen import stats_text


def window_of(sequences: list[int | None]) -> Window:
    window = Window(10)
    window.add([Sample(sequence, source=i * 100_000_000, received=i * 100_000_000 + 5, size=10, stamp=None)
                for i, sequence in enumerate(sequences)])
    return window


def test_the_topic_screen_says_the_loss_is_unknown_without_sequence_numbers() -> None:
    assert stats_text(window_of([None, None, None])).endswith("lost unknown")
    assert stats_text(window_of([1, 2, 4])).endswith("lost 1")


def test_the_plot_counts_no_loss_once_a_batch_came_without_sequence_numbers() -> None:
    from roc.tui.plot_screen import PlotScreen

    screen = PlotScreen.__new__(PlotScreen)  # its counting alone, without a running app
    screen.series, screen.received, screen.lost, screen.latest, screen.changed = [], 0, 0, 0.0, False
    screen.paused_at = None
    screen.take("/chatter", {"time": [1, 2], "values": {}, "lost": 2})
    assert screen.lost == 2
    screen.take("/chatter", {"time": [3], "values": {}, "lost": None})
    screen.take("/chatter", {"time": [4], "values": {}, "lost": 0})
    assert screen.lost is None and screen.received == 4
