"""roc bag record: record topics and services into a bag (like ros2 bag record): raw CDR as it
arrives, QoS adapted to each topic's publishers, topics picked up as they appear, every lost message
counted from the publishers' sequence numbers and reported at the end."""

from __future__ import annotations

import argparse
import datetime
import signal
import sys
from pathlib import Path

from roc.bag.compression import FORMATS, MODES
from roc.bag.reader import STORAGES
from roc.bag.selection import Selection
from roc.bag.writer import DEFAULT_STORAGE, WriteOptions, check_options
from roc.errors import EXIT_FAILURE, UsageError
from roc.render import plural, print_lines, print_text, table_lines


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("topics_positional", nargs="*", metavar="TOPIC", help="topics to record")
    parser.add_argument("-o", "--output", help="the bag directory to create (default: rosbag2_<date>-<time>)")
    parser.add_argument("-s", "--storage", default=DEFAULT_STORAGE, choices=sorted(STORAGES),
                        help=f"storage (default: {DEFAULT_STORAGE})")
    select = parser.add_argument_group("what to record")
    select.add_argument("--topics", nargs="+", default=[], metavar="TOPIC", help="topics to record")
    select.add_argument("--services", nargs="+", default=[], metavar="SERVICE",
                        help="services to record (their event topics; the nodes must enable service introspection)")
    select.add_argument("--topic-types", nargs="+", default=[], metavar="TYPE", help="record topics of these types")
    select.add_argument("-a", "--all", action="store_true", help="record every topic and service (not hidden ones)")
    select.add_argument("--all-topics", action="store_true", help="record every topic (not hidden ones)")
    select.add_argument("--all-services", action="store_true", help="record every service's events")
    select.add_argument("-e", "--regex", default="", help="record topics and services whose name this matches")
    select.add_argument("-x", "--exclude-regex", default="", help="leave out topics and services this matches")
    select.add_argument("--exclude-topics", nargs="+", default=[], metavar="TOPIC", help="topics to leave out")
    select.add_argument("--exclude-topic-types", nargs="+", default=[], metavar="TYPE",
                        help="topic types to leave out")
    select.add_argument("--exclude-services", nargs="+", default=[], metavar="SERVICE", help="services to leave out")
    select.add_argument("--include-hidden-topics", action="store_true", help="also record hidden topics")
    select.add_argument("--include-unpublished-topics", action="store_true",
                        help="also subscribe to selected topics that have no publisher")
    select.add_argument("-p", "--polling-interval", type=int, default=100, metavar="MS",
                        help="how often to look for new topics, in ms (default: 100)")
    parser.add_argument("--qos-profile-overrides-path", metavar="YAML",
                        help="QoS profiles to subscribe with, by topic (rosbag2's format)")
    files = parser.add_argument_group("files")
    files.add_argument("-b", "--max-bag-size", type=int, default=0, metavar="BYTES",
                       help="split the bag into files of this size (0: one file)")
    files.add_argument("-d", "--max-bag-duration", type=int, default=0, metavar="SECONDS",
                       help="split the bag into files of this duration (0: one file)")
    files.add_argument("--compression-mode", default="none", choices=MODES, help="compress each file or message")
    files.add_argument("--compression-format", default="", choices=FORMATS, help="compression format")
    files.add_argument("--storage-preset-profile", default="none", metavar="PROFILE",
                       help="mcap: none, fastwrite, zstd_fast, zstd_small; sqlite3: none, resilient")
    files.add_argument("--custom-data", nargs="*", default=[], metavar="KEY=VALUE",
                       help="store these in the bag's metadata (custom_data)")
    files.add_argument("--repeat-transient-local", nargs="*", metavar="TOPIC[=DEPTH]",
                       help="begin each split file with the latest DEPTH (default 1) messages of these topics, "
                            "so that each file plays alone (/tf_static, /map); without topics: of every topic "
                            "offered transient local")
    files.add_argument("--repeat-all-transient-local", nargs="?", type=int, const=1, default=0, metavar="DEPTH",
                       help="as --repeat-transient-local for every topic offered transient local (rosbag2's "
                            "spelling; DEPTH defaults to 1)")
    parser.add_argument("--start-paused", action="store_true", help="start paused (space resumes)")
    parser.add_argument("--use-sim-time", action="store_true",
                        help="stamp messages with /clock's time; nothing is written before the first /clock")
    parser.add_argument("--disable-keyboard-controls", action="store_true", help="no keyboard controls")


def _selection(args: argparse.Namespace) -> Selection:
    topics = args.topics or args.topics_positional
    if args.topics and args.topics_positional:
        raise UsageError("give topics either as arguments or with --topics, not both")
    topics = [t if t.startswith("/") else f"/{t}" for t in topics]
    selection = Selection(all_topics=args.all or args.all_topics, all_services=args.all or args.all_services,
                          topics=topics, topic_types=args.topic_types, services=args.services,
                          regex=args.regex, exclude_regex=args.exclude_regex, exclude_topics=args.exclude_topics,
                          exclude_topic_types=args.exclude_topic_types, exclude_services=args.exclude_services,
                          include_hidden_topics=args.include_hidden_topics)
    if not selection.selects_anything:
        raise UsageError("say what to record: topics, or one of --all, --all-topics, --all-services, --services, "
                         "--topic-types or --regex")
    any_set = args.all or args.all_topics or args.topic_types or args.regex
    if args.exclude_regex and not (any_set or args.all_services):
        raise UsageError("--exclude-regex needs --all, --all-topics, --topic-types, --all-services or --regex")
    if (args.exclude_topics or args.exclude_topic_types) and not any_set:
        raise UsageError("--exclude-topics and --exclude-topic-types need --all, --all-topics, --topic-types "
                         "or --regex")
    if args.exclude_services and not (args.all or args.all_services or args.regex):
        raise UsageError("--exclude-services needs --all, --all-services or --regex")
    return selection


def _custom_data(pairs: list[str]) -> dict[str, str]:
    data = {}
    for pair in pairs:
        key, equals, value = pair.partition("=")
        if not equals or not key:
            raise UsageError(f"--custom-data: '{pair}' is not KEY=VALUE")
        data[key] = value
    return data


def repeat_options(given: list[str] | None, every: int) -> tuple[dict[str, int], int]:
    """``--repeat-transient-local TOPIC[=DEPTH] ...`` as {topic: depth} and the depth of every transient
    local topic (``--repeat-all-transient-local``, or the option alone)."""
    if given is None:
        return {}, every
    if not given:
        return {}, every or 1
    depths = {}
    for entry in given:
        topic, equals, depth = entry.partition("=")
        if not topic or (equals and not depth.isdigit()) or (equals and int(depth) == 0):
            raise UsageError(f"--repeat-transient-local: '{entry}' is not TOPIC or TOPIC=DEPTH (a positive number)")
        depths[topic if topic.startswith("/") else f"/{topic}"] = int(depth) if equals else 1
    return depths, every


def _summary(result, uri: str) -> list[str]:
    metadata = result.metadata
    lines = [f"Recorded {plural(metadata.message_count, 'message')} on {plural(len(metadata.topics), 'topic')} "
             f"into {uri} ({plural(len(metadata.relative_file_paths), 'file')})"]
    if result.stats:
        rows = [[name, s.received, s.written, "unknown" if s.unsequenced else s.lost]
                for name, s in sorted(result.stats.items())]  # by name: topics are subscribed as discovered
        lines += table_lines(rows, header=["topic", "received", "written", "lost"])
    lost = sum(s.lost for s in result.stats.values())
    unknown = sum(1 for s in result.stats.values() if s.unsequenced)
    if unknown:
        known = f"; {lost} on the other topics" if unknown < len(result.stats) else ""
        lines.append(f"Lost messages: unknown on {plural(unknown, 'topic')} (the middleware gives no publication "
                     f"sequence numbers){known}")
    else:
        lines.append(f"Lost messages: {lost} (gaps in the publishers' sequence numbers)")
    if result.repeated:
        lines.append(f"Repeated at the start of split files: {result.repeated} (--repeat-transient-local)")
    if result.paused_dropped:
        lines.append(f"Not written while paused: {result.paused_dropped}")
    if result.before_clock_dropped:
        lines.append(f"Not written before the first /clock message: {result.before_clock_dropped}")
    return lines


def run(args: argparse.Namespace) -> int:
    from roc.bag.keyboard import Keyboard
    from roc.bag.qos import load_overrides

    uri = args.output or datetime.datetime.now().strftime("rosbag2_%Y_%m_%d-%H_%M_%S")
    if Path(uri).exists():
        raise UsageError(f"output folder '{uri}' already exists")
    if args.polling_interval <= 0:
        raise UsageError("--polling-interval must be positive")
    write = WriteOptions(storage=args.storage, max_bag_size=args.max_bag_size,
                         max_bag_duration=args.max_bag_duration * 1_000_000_000,
                         compression_mode=args.compression_mode, compression_format=args.compression_format,
                         preset=args.storage_preset_profile, custom_data=_custom_data(args.custom_data))
    write.repeat_transient_local, write.repeat_all_transient_local = repeat_options(
        args.repeat_transient_local, args.repeat_all_transient_local)
    check_options(write)
    selection = _selection(args)
    overrides = load_overrides(args.qos_profile_overrides_path) if args.qos_profile_overrides_path else {}

    from roc.bag.transport.recorder import Recorder, RecordOptions  # joins the ROS graph (rclpy)

    recorder = Recorder(RecordOptions(uri=uri, write=write, selection=selection, overrides=overrides,
                                      include_unpublished_topics=args.include_unpublished_topics,
                                      polling_interval=args.polling_interval / 1000, start_paused=args.start_paused,
                                      use_sim_time=args.use_sim_time),
                        report=lambda line: print_text(line + "\n"),
                        warn=lambda line: print_text(f"roc: warning: {line}\n", sys.stderr))
    for number in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(number, lambda *_: recorder.stop())
    keys = {"space": recorder.toggle_pause}
    with Keyboard(lambda key: keys[key]() if key in keys else None, enabled=not args.disable_keyboard_controls):
        result = recorder.run()
    print_lines(_summary(result, uri))
    if result.error:
        print_text(f"roc: error: {result.error}\n", sys.stderr)
        return EXIT_FAILURE
    return 0
