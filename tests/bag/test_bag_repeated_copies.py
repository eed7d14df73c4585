"""The copies of transient local messages that a split recording repeats at the start of each file
(--repeat-transient-local) told from their original: counted once, played once."""

from __future__ import annotations

import queue
from pathlib import Path

from helpers.bag import write_split_bag_with_tf_static

from roc.bag.reader import Bag, RepeatedCopies, repeated_copies


def test_the_copies_are_told_from_the_original_in_a_pass_over_the_bag(tmp_path: Path) -> None:
    write_split_bag_with_tf_static(tmp_path / "bag")
    with Bag(tmp_path / "bag") as bag:
        assert {topic.name: count for topic, count in bag.metadata.topics} == {"/tf_static": 4, "/data": 40}
        assert repeated_copies(bag) == {"/tf_static": 3}
        third_file = bag.metadata.files[2].starting_time
        is_copy = RepeatedCopies(bag)  # a pass from the third file: its first copy is the pass's original
        kept = [m.topic for m in bag.messages(["/tf_static"], start=third_file) if not is_copy(m)]
        assert kept == ["/tf_static"]


def played(bag_path: Path, start_file: int) -> tuple[list[str], int]:
    """The topics of what one pass of the player reads from the start of file ``start_file``, and the
    copies it leaves out."""
    from roc.bag.transport.player import Player, PlayOptions

    player = Player(PlayOptions(bag=str(bag_path)), report=print, warn=print)
    ready: queue.Queue = queue.Queue()
    with Bag(bag_path) as bag:
        player._read(bag, ["/tf_static", "/data"], bag.metadata.files[start_file].starting_time, None, ready)
    topics = []
    while (message := ready.get()) is not None:
        topics.append(message.topic)
    return topics, player._repeated


def test_playback_publishes_a_repeated_message_once(tmp_path: Path) -> None:
    write_split_bag_with_tf_static(tmp_path / "bag")
    topics, repeated = played(tmp_path / "bag", 0)
    assert (topics.count("/tf_static"), topics.count("/data"), repeated) == (1, 40, 3)
    topics, repeated = played(tmp_path / "bag", 2)  # from the middle: the copy there stands for the original
    assert (topics.count("/tf_static"), topics.count("/data"), repeated) == (1, 20, 1)
