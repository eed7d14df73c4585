"""roc bag play: play a bag back (like ros2 bag play): each topic with its recorded QoS, at the
recorded times scaled by --rate; space pauses and resumes, the right arrow plays the next message,
up and down change the rate."""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import sys

from roc.bag.reader import STORAGES
from roc.bag.selection import Selection
from roc.errors import UsageError
from roc.render import plural, print_lines, print_text


def _positive(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
    if value <= 0:
        raise argparse.ArgumentTypeError(f"{text} is not positive")
    return value


def _not_negative(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"{text} is negative")
    return value


def _count(text: str) -> int:
    if not text.isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number of at least 1")
    return int(text)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bag_path", metavar="BAG", help="a bag directory, or a .mcap or .db3 file")
    parser.add_argument("-s", "--storage", choices=sorted(STORAGES), help="storage of the bag (default: found)")
    parser.add_argument("-r", "--rate", type=_positive, default=1.0, help="playback rate (default: 1.0)")
    parser.add_argument("-l", "--loop", action="store_true", help="play the bag again and again")
    parser.add_argument("--clock", type=_positive, nargs="?", const=40.0, default=0.0, metavar="HZ",
                        help="publish the playback time on /clock at HZ (default 40); /clock of the bag is not played")
    select = parser.add_argument_group("what to play")
    select.add_argument("--topics", nargs="+", default=[], metavar="TOPIC", help="only these topics")
    select.add_argument("--services", nargs="+", default=[], metavar="SERVICE", help="only these services' events")
    select.add_argument("-e", "--regex", default="", help="only topics and services this matches")
    select.add_argument("-x", "--exclude-regex", default="", help="leave out topics and services this matches")
    select.add_argument("--exclude-topics", nargs="+", default=[], metavar="TOPIC", help="leave out these topics")
    select.add_argument("--exclude-services", nargs="+", default=[], metavar="SERVICE",
                        help="leave out these services' events")
    parser.add_argument("-m", "--remap", nargs="+", default=[], metavar="OLD:=NEW", help="publish topics renamed")
    parser.add_argument("--qos-profile-overrides-path", metavar="YAML",
                        help="QoS profiles to publish with, by topic (rosbag2's format)")
    parser.add_argument("--start-offset", type=_not_negative, default=0.0, metavar="SECONDS",
                        help="start this many seconds into the bag")
    parser.add_argument("-d", "--delay", type=_not_negative, default=0.0, metavar="SECONDS",
                        help="wait this long before playing (each loop)")
    parser.add_argument("--playback-duration", type=float, default=-1.0, metavar="SECONDS",
                        help="play this many seconds of the bag (negative: all)")
    parser.add_argument("--playback-until-sec", type=float, default=-1.0, metavar="SECONDS",
                        help="play up to this bag time, in seconds since the epoch (negative: to the end)")
    parser.add_argument("--read-ahead-queue-size", type=int, default=1000, metavar="N",
                        help="messages read ahead of playback (default: 1000)")
    parser.add_argument("--wait-for-all-acked", type=int, default=-1, metavar="MS",
                        help="at the end, wait up to MS ms until reliable subscribers acknowledged every message "
                             "(0: as long as it takes; default: do not wait)")
    parser.add_argument("--wait-for-subscribers", type=_count, nargs="?", const=1, default=0, metavar="N",
                        help="play nothing until every topic played has at least N subscribers (default 1)")
    parser.add_argument("-p", "--start-paused", action="store_true", help="start paused (space resumes)")
    parser.add_argument("--disable-keyboard-controls", action="store_true", help="no keyboard controls")


def _remaps(rules: list[str]) -> list[str]:
    for rule in rules:
        old, separator, new = rule.partition(":=")
        if not separator or not old or not new:
            raise UsageError(f"--remap: '{rule}' is not OLD:=NEW")
    return rules


def _selection(args: argparse.Namespace) -> Selection | None:
    if not (args.topics or args.services or args.regex or args.exclude_regex or args.exclude_topics
            or args.exclude_services):
        return None
    everything = not (args.topics or args.services or args.regex)
    topics = [t if t.startswith("/") else f"/{t}" for t in args.topics]
    return Selection(all_topics=everything, all_services=everything, topics=topics + args.topics,
                     services=args.services, regex=args.regex, exclude_regex=args.exclude_regex,
                     exclude_topics=[t if t.startswith("/") else f"/{t}" for t in args.exclude_topics]
                     + args.exclude_topics, exclude_services=args.exclude_services, include_hidden_topics=True)


def _summary(result) -> list[str]:
    total = sum(result.published.values())
    lines = [f"Played {plural(total, 'message')} on {plural(len(result.published), 'topic')}"]
    if result.repeated:
        lines.append(f"Not played again: {result.repeated} of the transient local messages a split recording repeats "
                     "at the start of each file (--repeat-transient-local); their original was played")
    if result.lateness_ns:
        late = sorted(abs(x) for x in result.lateness_ns)
        p99 = late[min(len(late) - 1, int(len(late) * 0.99))]
        lines.append(f"Timing against the recorded times: median {statistics.median(late) / 1e6:.3f} ms, "
                     f"p99 {p99 / 1e6:.3f} ms, max {late[-1] / 1e6:.3f} ms late")
    return lines


def _start_again_with_missing_types(options, command_words: list[str]) -> None:
    """Build the types the bag needs and the environment lacks from the bag's own definitions, then
    replace this process with the same command in an environment that has them (generated libraries
    load only through the environment a process starts with). Returns when nothing is missing."""
    from roc.bag.built_types import built_prefix, environment_with
    from roc.bag.reader import Bag
    from roc.bag.transport.player import played_topics

    with Bag(options.bag, options.storage) as bag:
        types = {topic.type for topic in played_topics(bag, options) if not topic.is_service_event}
        definitions = [d for name, d in bag.definitions().items() if name in types]
    prefix = built_prefix(definitions, report=lambda line: print_text(f"roc: {line}\n", sys.stderr))
    if prefix is None:
        return
    sys.stdout.flush()
    sys.stderr.flush()
    os.execve(sys.executable, [sys.executable, "-m", "roc", *command_words], environment_with(prefix, dict(os.environ)))


def run(args: argparse.Namespace) -> int:
    from roc.bag.keyboard import Keyboard
    from roc.bag.qos import load_overrides

    if args.read_ahead_queue_size < 1:
        raise UsageError("--read-ahead-queue-size must be at least 1")
    overrides = load_overrides(args.qos_profile_overrides_path) if args.qos_profile_overrides_path else {}

    from roc.bag.transport.player import RATE_STEP, Player, PlayOptions  # joins the ROS graph (rclpy)

    options = PlayOptions(
        bag=args.bag_path, storage=args.storage, rate=args.rate, loop=args.loop, clock_hz=args.clock,
        selection=_selection(args), remaps=_remaps(args.remap), overrides=overrides, start_offset=args.start_offset,
        delay=args.delay, playback_duration=args.playback_duration,
        playback_until=int(args.playback_until_sec * 1e9) if args.playback_until_sec >= 0 else -1,
        read_ahead=args.read_ahead_queue_size, start_paused=args.start_paused,
        wait_for_all_acked=args.wait_for_all_acked, wait_for_subscribers=args.wait_for_subscribers)
    from roc.bag.built_types import BUILT_PREFIX_VARIABLE

    if not os.environ.get(BUILT_PREFIX_VARIABLE):
        _start_again_with_missing_types(options, args.command_words)
    player = Player(options, report=lambda line: print_text(line + "\n"),
                    warn=lambda line: print_text(f"roc: warning: {line}\n", sys.stderr))
    for number in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(number, lambda *_: player.stop())
    keys = {"space": player.toggle_pause, "right": player.play_next,
            "up": lambda: player.change_rate(RATE_STEP), "down": lambda: player.change_rate(1 / RATE_STEP)}
    with Keyboard(lambda key: keys[key]() if key in keys else None, enabled=not args.disable_keyboard_controls):
        result = player.run()
    print_lines(_summary(result))
    return 0
