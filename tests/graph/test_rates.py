"""Unit tests of topic hz/bw/delay's arithmetic (roc.ros.rates) and of reading a header stamp from CDR."""

from __future__ import annotations

import pytest

from roc.ros.rates import Sample, Window, samples, size_text

MS = 1_000_000


def _sample(sequence: int, source_ms: float, received_ms: float | None = None, size: int = 10,
            stamp_ms: float | None = None) -> Sample:
    received = source_ms if received_ms is None else received_ms
    return Sample(sequence, int(source_ms * MS), int(received * MS), size,
                  None if stamp_ms is None else int(stamp_ms * MS))


def test_rate_is_the_publishers_despite_losses_and_late_reception() -> None:
    window = Window(100)
    # 100 Hz publisher; messages 3 and 4 lost; reception jittery (a busy subscriber).
    window.add([_sample(1, 0, 5), _sample(2, 10, 11), _sample(5, 40, 70), _sample(6, 50, 71)])
    rate = window.rate()
    assert rate["rate"] == pytest.approx(100.0)
    assert (rate["min"], rate["max"], rate["window"]) == (pytest.approx(0.01), pytest.approx(0.03), 4)
    assert window.lost == 2
    assert window.rate(wall_time=True)["rate"] == pytest.approx(5 / 0.066)


def test_loss_is_unknown_not_zero_without_sequence_numbers() -> None:
    window = Window(10)  # Cyclone DDS gives no publication sequence numbers
    window.add([Sample(None, n * 10 * MS, n * 10 * MS, 10, None) for n in range(5)])
    assert window.rate()["rate"] == pytest.approx(100.0)
    assert window.known_lost() is None
    sequenced = Window(10)
    sequenced.add([_sample(1, 0), _sample(3, 20)])
    assert sequenced.known_lost() == 1


def test_window_keeps_the_last_messages_and_needs_two() -> None:
    window = Window(3)
    window.add([_sample(1, 0)])
    assert window.rate() is None and window.bandwidth() is None
    window.add([_sample(n, n * 100) for n in range(2, 7)])
    assert [s.sequence for s in window.samples] == [4, 5, 6]
    assert window.rate()["rate"] == pytest.approx(10.0)


def test_interleaved_publishers_fall_back_to_counting() -> None:
    window = Window(10)
    window.add([_sample(5, 0), _sample(1, 50), _sample(6, 100), _sample(2, 150)])
    assert window.rate()["rate"] == pytest.approx(3 / 0.15)


def test_a_history_arriving_after_newer_messages_neither_reverses_nor_inflates_the_rate() -> None:
    window = Window(10)  # a live publisher at 10 Hz, then another's transient local history (older)
    window.add([_sample(100, 1000), _sample(101, 1100), _sample(102, 1200), _sample(1, 700), _sample(2, 800)])
    rate = window.rate()
    assert rate["rate"] == pytest.approx(4 / 0.5)
    assert (rate["min"], rate["max"]) == (pytest.approx(0.1), pytest.approx(0.2))  # none negative
    window = Window(10)  # the history first: the sequence numbers rise, but from two publishers
    window.add([_sample(5, 0), _sample(6, 100), _sample(1000, 50), _sample(1001, 150)])
    assert window.rate()["rate"] == pytest.approx(3 / 0.15)


def test_bandwidth_and_delay() -> None:
    window = Window(10)
    window.add([_sample(n, n * 100, size=size, stamp_ms=n * 100 - 2) for n, size in ((1, 100), (2, 300), (3, 200))])
    bandwidth = window.bandwidth()
    # the bytes that came after the first message over the 0.2 s since it came (3 messages, 2 intervals)
    assert bandwidth == {"bytes_per_second": pytest.approx(500 / 0.2), "messages": 3, "mean": 200, "min": 100,
                         "max": 300}
    steady = Window(10)  # ros2's test: a 52-byte message at 1 Hz is 52 B/s from the second message on
    steady.add([_sample(1, 0, size=52), _sample(2, 1000, size=52)])
    assert size_text(steady.bandwidth()["bytes_per_second"]) == "52 B"
    delay = window.delay()
    assert (delay["delay"], delay["min"], delay["max"], delay["window"]) == (
        pytest.approx(0.002), pytest.approx(0.002), pytest.approx(0.002), 3)


def test_samples_from_batch_columns_and_sizes_as_ros2_prints_them() -> None:
    columns = {"sequence": [1, 2], "source": [10, 20], "received": [11, 21], "size": [5, 6], "stamp": [None, 3]}
    assert samples(columns) == [Sample(1, 10, 11, 5, None), Sample(2, 20, 21, 6, 3)]
    assert [size_text(v) for v in (28, 999.4, 1500, 2_000_000)] == ["28 B", "999 B", "1.50 KB", "2.00 MB"]


def test_header_stamp_is_read_from_cdr() -> None:
    from rclpy.serialization import serialize_message
    from std_msgs.msg import Header

    from roc.ros.dataplane import header_stamp_ns

    header = Header(frame_id="map")
    header.stamp.sec, header.stamp.nanosec = 12, 345
    assert header_stamp_ns(serialize_message(header)) == 12_000_000_345
    assert header_stamp_ns(b"\x00\x01") is None


def _columns(messages: list[tuple[str, int, float]], size: int = 10) -> dict[str, list]:
    """A ``stats`` batch's columns of (publisher, sequence, source ms) messages, received as sent."""
    return {"sequence": [m[1] for m in messages], "source": [int(m[2] * MS) for m in messages],
            "received": [int(m[2] * MS) for m in messages], "size": [size] * len(messages),
            "stamp": [None] * len(messages), "publisher": [m[0] for m in messages]}


def _arriving(window: Window, messages: list[tuple[str, int, float]]):
    """Add ``messages`` to ``window`` in time order, one at a time, yielding each after it is added."""
    for message in sorted(messages, key=lambda m: m[2]):
        window.add(samples(_columns([message])))
        yield message


def test_several_publishers_read_their_sum_from_the_second_message_of_each() -> None:
    """Issue 51: a 1 Hz and a 2 Hz publisher, the second starting 0.3 s after the first, are 3 Hz as soon
    as each was heard twice (counted over their span, the messages read 3.07, 2.86, 3.11 Hz...)."""
    one = [("a", 10 + n, n * 1000.0) for n in range(6)]
    two = [("b", 500 + n, 300 + n * 500.0) for n in range(10)]
    window, heard, rates = Window(10000), {"a": 0, "b": 0}, []
    for publisher, _, _ in _arriving(window, one + two):
        heard[publisher] += 1
        if min(heard.values()) >= 2:
            rates.append(window.frequency())
            assert window.rate()["rate"] == pytest.approx(3.0)
            assert window.bandwidth()["bytes_per_second"] == pytest.approx(30.0)  # 10-byte messages
        else:
            assert window.frequency() is None  # one was heard once: unknown, not 1 or 2 Hz, in the first 2 s
    assert rates == [pytest.approx(3.0)] * len(rates) and len(rates) == 13  # a's second message on
    assert window.lost == 0
    rate = window.rate()  # the statistics are the topic's: intervals between its consecutive messages
    assert (rate["min"], rate["max"], rate["window"]) == (pytest.approx(0.2), pytest.approx(0.5), 16)


def test_losses_are_counted_per_publisher() -> None:
    window = Window(100)
    window.add(samples(_columns([("a", 1, 0), ("b", 900, 10), ("a", 2, 100), ("b", 901, 110), ("a", 4, 300),
                                 ("a", 5, 400), ("b", 904, 410)])))
    assert (window.lost, window.known_lost()) == (3, 3)  # a's 3 and b's 902 and 903
    assert window.frequency() == pytest.approx(20.0)  # each publishes at 10 Hz, the lost messages included


def test_a_publisher_heard_once_counts_from_its_second_message() -> None:
    window = Window(100)
    window.add(samples(_columns([("a", n, n * 1000.0) for n in range(4)])))  # 1 Hz for 3 s
    assert window.frequency() == pytest.approx(1.0)
    window.add(samples(_columns([("b", 7, 3100)])))  # a new publisher, heard once: it adds nothing yet
    assert window.frequency() == pytest.approx(1.0)
    window.add(samples(_columns([("b", 8, 3600)])))
    assert window.frequency() == pytest.approx(3.0)
    young = Window(100)  # in a measure's first seconds, one heard once makes the rate unknown, not low
    young.add(samples(_columns([("a", 1, 0), ("b", 1, 400), ("a", 2, 1000)])))
    assert young.frequency() is None and young.rate() is None and young.bandwidth() is None
    young.add(samples(_columns([("a", 3, 2000), ("a", 4, 3000)])))  # b said one thing only: a's rate
    assert young.frequency() == pytest.approx(1.0)


def test_a_stopped_publisher_counts_no_more() -> None:
    window = Window(10000)
    window.add(samples(_columns([("a", n, n * 500.0) for n in range(7)] + [("b", n, 250 + n * 500.0)
                                                                         for n in range(7)])))
    assert window.frequency() == pytest.approx(4.0)
    window.add(samples(_columns([("a", n, n * 500.0) for n in range(7, 10)])))  # b stopped at 3.25 s
    assert window.frequency() == pytest.approx(4.0)  # silent for 1.25 s: maybe late
    window.add(samples(_columns([("a", n, n * 500.0) for n in range(10, 40)])))
    assert window.frequency() == pytest.approx(2.0)  # silent for three of its intervals and more: stopped
    assert window.rate()["window"] == 47  # its messages stay in the window's statistics


def test_a_slow_publisher_beside_fast_ones_counts_from_its_last_two_messages() -> None:
    window = Window(50)  # half a second of the 100 Hz publisher: one message of the 1 Hz one at most
    fast = [("fast", n, n * 10.0) for n in range(400)]
    slow = [("slow", n, 5 + n * 1000.0) for n in range(4)]
    window.add(samples(_columns(sorted(fast + slow, key=lambda m: m[2]))))
    assert window.frequency() == pytest.approx(101.0)
