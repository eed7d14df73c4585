"""Playing a bag back (``roc bag play``): each topic published with the QoS it was recorded with
(rosbag2's rule: the recorded offer when all publishers agreed, else the default; or an override),
its raw CDR as stored, at the recorded times scaled by the rate. A reader thread keeps up to
``read_ahead`` messages ready; the main thread sleeps until each message is due and publishes it.
Pause, play-next and rate changes come from the keyboard (or any caller of ``toggle_pause``,
``play_next``, ``change_rate``); ``--clock`` publishes the playback time on /clock.

Types come from the environment: rclpy (Jazzy) can only publish a type whose generated code is
installed. The verb builds the types the environment lacks from the bag's own definitions first
(roc.bag.built_types); a topic whose type is still missing (no ``ros2msg`` definition in the bag) is
left out with a warning that says so."""

from __future__ import annotations

import queue
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from roc.bag.message import Message
from roc.bag.metadata import Topic
from roc.bag.qos import offer_for_recorded
from roc.bag.reader import Bag, RepeatedCopies
from roc.bag.selection import Selection
from roc.bag.transport.ros_qos import profile
from roc.errors import RocError
from roc.render import plural
from roc.ros.graph import Graph
from roc.ros.protocol import task_node_name
from roc.ros.types import UnknownTypeError, message_class

SPIN_NS = 100_000  # the last 0.1 ms before a message is due is waited without sleeping (sleep overshoots)
SLICE_S = 0.05  # a long wait is cut in slices, to notice a pause, a rate change or a stop
RATE_STEP = 1.1  # up/down arrow: rate times or divided by this
# DDS matches each side on its own: a new subscriber's reader, matched by the player's writer, may need a
# moment more to match the writer in turn, and a volatile reader drops what came before it did
MATCH_GRACE_S = 0.5
CLOCK_TOPIC = "/clock"


@dataclass
class PlayOptions:
    bag: str
    storage: str | None = None
    rate: float = 1.0
    loop: bool = False
    clock_hz: float = 0.0
    selection: Selection | None = None  # None: every topic
    remaps: list[str] = field(default_factory=list)  # OLD:=NEW rules, applied by rcl to the player's node
    overrides: dict[str, dict[str, Any]] = field(default_factory=dict)
    start_offset: float = 0.0  # seconds
    delay: float = 0.0  # seconds before each play
    playback_duration: float = -1.0  # seconds; negative: to the end
    playback_until: int = -1  # ns since the epoch; negative: to the end
    read_ahead: int = 1000
    start_paused: bool = False
    wait_for_all_acked: int = -1  # ms to wait at the end for reliable subscribers to have it all (0: forever)
    wait_for_subscribers: int = 0  # play nothing before every topic played has this many subscribers


@dataclass
class PlayResult:
    published: dict[str, int]
    lateness_ns: list[int]  # how late each message went out against its scheduled time
    skipped: list[str]
    repeated: int = 0  # copies of transient local messages a split recording repeated, not played again


def _absolute(name: str) -> str:
    return name if name.startswith("/") else f"/{name}"


def played_topics(bag: Bag, options: PlayOptions) -> list[Topic]:
    """The bag's topics the options select (/clock of the bag is left out when the player makes one)."""
    selection = options.selection
    return [topic for topic in bag.topics()
            if (selection is None or selection.takes(_absolute(topic.name), topic.type)
                or selection.takes(topic.name, topic.type))
            and not (options.clock_hz > 0 and _absolute(topic.name) == CLOCK_TOPIC)]


class Player:
    def __init__(self, options: PlayOptions, report: Callable[[str], None], warn: Callable[[str], None]) -> None:
        if options.rate <= 0:
            raise RocError("the rate must be positive")
        self.options = options
        self._report, self._warn = report, warn
        self._changed = threading.Condition()
        self._paused = options.start_paused
        self._next = 0  # messages to play at once while paused (right arrow)
        self._rate = options.rate
        self._stopping = False
        self._repeated = 0  # copies left out (RepeatedCopies)
        # The playback clock: bag time = anchor_bag + (now - anchor_wall) * rate, frozen while paused.
        self._anchor_wall = time.perf_counter_ns()
        self._anchor_bag = 0

    # ---- controls (any thread) ----------------------------------------------------------------
    def stop(self) -> None:
        with self._changed:
            self._stopping = True
            self._changed.notify_all()

    def toggle_pause(self) -> None:
        with self._changed:
            now_bag = self._bag_now()
            self._paused = not self._paused
            self._anchor(now_bag)
            self._changed.notify_all()
        self._report("Paused" if self._paused else "Resumed")

    def play_next(self) -> None:
        with self._changed:
            if self._paused:
                self._next += 1
                self._changed.notify_all()

    def change_rate(self, factor: float) -> None:
        with self._changed:
            now_bag = self._bag_now()
            self._rate *= factor
            self._anchor(now_bag)
            self._changed.notify_all()
        self._report(f"Rate: {self._rate:.3f}")

    # ---- the playback clock ---------------------------------------------------------------------
    def _anchor(self, bag_time: int) -> None:
        self._anchor_wall, self._anchor_bag = time.perf_counter_ns(), bag_time

    def _bag_now(self) -> int:
        if self._paused:
            return self._anchor_bag
        return self._anchor_bag + int((time.perf_counter_ns() - self._anchor_wall) * self._rate)

    def _due(self, log_time: int) -> int:
        return self._anchor_wall + int((log_time - self._anchor_bag) / self._rate)

    def _wait_for(self, message: Message) -> bool:
        """Wait until ``message`` is due (or may go out, paused, by play-next); False to stop."""
        with self._changed:
            while True:
                if self._stopping:
                    return False
                if self._paused:
                    if self._next:
                        self._next -= 1
                        self._anchor(message.log_time)
                        return True
                    self._changed.wait(SLICE_S)
                    continue
                remaining = self._due(message.log_time) - time.perf_counter_ns()
                if remaining <= SPIN_NS:
                    break
                self._changed.wait(min(SLICE_S, (remaining - SPIN_NS) / 1e9))
        due = self._due(message.log_time)
        while time.perf_counter_ns() < due:
            pass
        return True

    # ---- playing --------------------------------------------------------------------------------
    def _publishers(self, graph: Graph, bag: Bag) -> tuple[dict[str, Any], list[str]]:
        options = self.options
        publishers: dict[str, Any] = {}
        skipped = []
        for topic in played_topics(bag, options):
            try:
                cls = message_class(topic.type)
            except UnknownTypeError:
                skipped.append(topic.name)
                self._warn(f"not playing {topic.name}: its type {topic.type} is not installed here, and the bag "
                           "holds no message definition of it roc could build (rclpy can only publish types whose "
                           "generated code is installed); install or source its package")
                continue
            override = options.overrides.get(_absolute(topic.name)) or options.overrides.get(topic.name)
            qos = override
            if qos is None:
                qos, mixed = offer_for_recorded(topic.offered_qos_profiles)
                if mixed:
                    self._warn(f"the publishers of {topic.name} offered different QoS profiles when it was "
                               "recorded: playing it with the default profile")
            publishers[topic.name] = graph.node.create_publisher(cls, topic.name, profile(qos))
        return publishers, skipped

    def _read(self, bag: Bag, topics: list[str], start: int, end: int | None, ready: queue.Queue) -> None:
        """Read one pass's messages into ``ready``, less the copies a split recording repeated of messages
        this pass played (a transient local publisher keeps them for late subscribers already)."""
        is_copy = RepeatedCopies(bag)
        try:
            for message in bag.messages(topics, start, end):
                if is_copy(message):
                    self._repeated += 1
                    continue
                while True:
                    try:
                        ready.put(message, timeout=SLICE_S)
                        break
                    except queue.Full:
                        if self._stopping:
                            return
                if self._stopping:
                    return
            ready.put(None)
        except Exception as error:  # noqa: BLE001 - handed to the main thread, which reports it
            ready.put(error)

    def _clock(self, graph: Graph) -> None:
        from builtin_interfaces.msg import Time
        from rclpy.qos import QoSProfile
        from rosgraph_msgs.msg import Clock

        publisher = graph.node.create_publisher(Clock, CLOCK_TOPIC, QoSProfile(depth=1))
        period = 1.0 / self.options.clock_hz
        while not self._stopping:
            with self._changed:
                now = self._bag_now()
            publisher.publish(Clock(clock=Time(sec=now // 1_000_000_000, nanosec=now % 1_000_000_000)))
            with self._changed:
                self._changed.wait(period)

    def run(self) -> PlayResult:
        options = self.options
        published: dict[str, int] = {}
        lateness: list[int] = []
        with Bag(options.bag, options.storage) as bag:
            # the remappings are the node's, as rosbag2 passes them to its player: to its topics and /clock;
            # a node named for what it does (rosbag2's is rosbag2_player), listed as any other
            remaps = [word for rule in options.remaps for word in ("--remap", rule)]
            graph = Graph(task_node_name("bag_play"), arguments=["--ros-args", *remaps])
            try:
                publishers, skipped = self._publishers(graph, bag)
                if not publishers:
                    raise RocError(f"{bag.path}: nothing to play" + (" (no topic's type is installed)"
                                                                     if skipped else " (no topic selected)"))
                start = bag.metadata.starting_time + int(options.start_offset * 1e9)
                ends = [t for t in (start + int(options.playback_duration * 1e9) if options.playback_duration >= 0
                                    else None, options.playback_until if options.playback_until >= 0 else None)
                        if t is not None]
                end = min(ends) if ends else None
                if options.wait_for_subscribers > 0 and not self._wait_for_subscribers(publishers):
                    return PlayResult(published, lateness, skipped, self._repeated)
                with self._changed:
                    self._anchor(start)
                if options.clock_hz > 0:
                    threading.Thread(target=self._clock, args=(graph,), name="roc-clock", daemon=True).start()
                if self._paused:
                    self._report("Paused (space resumes, right arrow plays the next message)")
                while True:
                    if not self._play_once(bag, publishers, start, end, published, lateness):
                        break
                    if not options.loop or self._stopping:
                        break
                if options.wait_for_all_acked >= 0:
                    self._wait_for_acks(publishers.values())
            finally:
                self.stop()
                graph.close()
        return PlayResult(published, lateness, skipped, self._repeated)

    def _wait_for_subscribers(self, publishers: dict[str, Any]) -> bool:
        """Wait until each publisher has matched as many subscriptions as asked (its own count, not the
        graph's: a subscription another node already sees may not have matched the player yet), then
        MATCH_GRACE_S more; False if stopped."""
        wanted = self.options.wait_for_subscribers
        waiting = sorted(publishers)
        self._report(f"Waiting for {'a subscriber' if wanted == 1 else f'{wanted} subscribers'} on each of "
                     f"{plural(len(waiting), 'topic')}")
        with self._changed:
            while waiting and not self._stopping:
                waiting = [name for name in waiting if publishers[name].get_subscription_count() < wanted]
                if waiting:
                    self._changed.wait(SLICE_S)
            self._changed.wait_for(lambda: self._stopping, MATCH_GRACE_S)
            return not self._stopping

    def _wait_for_acks(self, publishers) -> None:
        from rclpy.duration import Duration

        timeout = Duration(seconds=self.options.wait_for_all_acked / 1000 if self.options.wait_for_all_acked
                           else 10 ** 9)
        for publisher in publishers:
            if not self._stopping and not publisher.wait_for_all_acked(timeout):
                self._warn(f"{publisher.topic_name}: not every subscriber acknowledged every message in time")

    def _play_once(self, bag: Bag, publishers: dict[str, Any], start: int, end: int | None,
                   published: dict[str, int], lateness: list[int]) -> bool:
        """One pass over the bag; False when stopped."""
        if self.options.delay > 0:
            with self._changed:
                self._changed.wait_for(lambda: self._stopping, self.options.delay)
        ready: queue.Queue = queue.Queue(maxsize=max(1, self.options.read_ahead))
        reader = threading.Thread(target=self._read, args=(bag, list(publishers), start, end, ready),
                                  name="roc-bag-reader", daemon=True)
        reader.start()
        try:
            item = ready.get()  # the clock starts once the first message is read (opening files takes time)
            with self._changed:
                self._anchor(start)
            while True:
                if item is None:
                    return True
                if isinstance(item, Exception):
                    raise item
                if not self._wait_for(item):
                    return False
                publishers[item.topic].publish(item.data)
                if not self._paused:
                    lateness.append(time.perf_counter_ns() - self._due(item.log_time))
                published[item.topic] = published.get(item.topic, 0) + 1
                item = ready.get()
        finally:
            if reader.is_alive():
                self._stopping_reader(ready)
            reader.join(timeout=2)

    def _stopping_reader(self, ready: queue.Queue) -> None:
        """Let a reader blocked on a full queue notice the stop."""
        while True:
            try:
                ready.get_nowait()
            except queue.Empty:
                return
