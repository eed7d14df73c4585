"""roc bag record's summary of lost messages: counted from the publishers' sequence numbers, and unknown,
never 0, on topics whose middleware gives none (Cyclone DDS)."""

from __future__ import annotations

from types import SimpleNamespace

from roc.bag.transport.recorder import TopicStats
from roc.commands.bag.record import _summary


def result(stats: dict[str, TopicStats]) -> SimpleNamespace:
    metadata = SimpleNamespace(message_count=sum(s.written for s in stats.values()), topics=list(stats),
                               relative_file_paths=["run_0.mcap"])
    return SimpleNamespace(metadata=metadata, stats=stats, repeated=0, paused_dropped=0, before_clock_dropped=0)


def test_lost_messages_are_unknown_on_topics_without_sequence_numbers() -> None:
    lines = _summary(result({"/a": TopicStats(received=5, written=5, lost=2),
                             "/b": TopicStats(received=3, written=3, unsequenced=3)}), "run")
    assert lines[-1] == ("Lost messages: unknown on 1 topic (the middleware gives no publication sequence numbers); "
                         "2 on the other topics")
    assert lines[-2].split() == ["/b", "3", "3", "unknown"]
    only = _summary(result({"/b": TopicStats(received=3, written=3, unsequenced=3)}), "run")
    assert only[-1] == "Lost messages: unknown on 1 topic (the middleware gives no publication sequence numbers)"


def test_lost_messages_are_counted_from_sequence_numbers() -> None:
    lines = _summary(result({"/a": TopicStats(received=5, written=5, lost=0)}), "run")
    assert lines[-1] == "Lost messages: 0 (gaps in the publishers' sequence numbers)"


def test_topics_are_listed_by_name_whatever_order_they_were_discovered_in() -> None:
    lines = _summary(result({"/tf_static": TopicStats(received=1, written=1),
                             "/tf": TopicStats(received=9, written=9)}), "run")
    assert [line.split()[0] for line in lines[1:4]] == ["topic", "/tf", "/tf_static"], lines
