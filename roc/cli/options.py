"""Option groups shared by several verbs, defined once: discovery and selection, where packages are
built and installed, and the output format."""

from __future__ import annotations

import argparse

# Options whose values are passed through to a tool and may themselves start with a dash.
# (--catkin-cmake-args too: roc rejects it, and its values must not be mistaken for options of roc)
PASSTHROUGH_OPTIONS = ("--cmake-args", "--ament-cmake-args", "--ctest-args", "--pytest-args", "--catkin-cmake-args")


def add_format_argument(parser: argparse.ArgumentParser, formats: tuple[str, ...] = ("text", "json")) -> None:
    parser.add_argument("--format", choices=formats, default="text",
                        help="output format (default: text); json is stable for scripts")


def add_selection_arguments(parser: argparse.ArgumentParser) -> None:
    """Discovery and selection options, as in colcon (``--packages-start``/``-end`` spelled as colcon 0.21),
    on every verb that selects packages: the ones that select by the last build or test result too
    (colcon-test-result adds them to every verb, as ``build --packages-select-test-failures``)."""
    discovery = parser.add_argument_group("discovery")
    discovery.add_argument("--base-paths", nargs="*", metavar="PATH",
                           help="base paths to crawl recursively for packages (default: the workspace root)")
    discovery.add_argument("--paths", nargs="*", metavar="PATH",
                           help="package directories to use (shell wildcards allowed, e.g. 'src/*')")
    discovery.add_argument("--packages-ignore", nargs="*", metavar="PKG_NAME",
                           help="ignore packages as if they were not discovered")
    discovery.add_argument("--packages-ignore-regex", nargs="*", metavar="PATTERN",
                           help="ignore packages whose name matches any of the patterns")
    group = parser.add_argument_group("package selection")
    add = group.add_argument
    add("--packages-up-to", nargs="*", metavar="PKG_NAME", help="only these packages and their recursive dependencies")
    add("--packages-up-to-regex", nargs="*", metavar="PATTERN",
        help="only packages matching a pattern and their recursive dependencies")
    add("--packages-above", nargs="*", metavar="PKG_NAME",
        help="only these packages and the packages that recursively depend on them")
    add("--packages-above-and-dependencies", nargs="*", metavar="PKG_NAME",
        help="as --packages-above, plus the recursive dependencies of all of those")
    add("--packages-above-depth", nargs="+", metavar=("DEPTH", "PKG_NAME"),
        help="as --packages-above, but only up to DEPTH levels of dependents")
    add("--packages-select-by-dep", nargs="*", metavar="DEP_NAME",
        help="only packages that (recursively) depend on any of these")
    add("--packages-skip-by-dep", nargs="*", metavar="DEP_NAME",
        help="skip packages that (recursively) depend on any of these")
    add("--packages-skip-up-to", nargs="*", metavar="PKG_NAME",
        help="skip these packages and their recursive dependencies")
    previous = group.add_mutually_exclusive_group()
    previous.add_argument("--packages-select-build-failed", action="store_true",
                          help="only packages whose last build failed (aborted ones are not failures)")
    previous.add_argument("--packages-skip-build-finished", action="store_true",
                          help="skip packages whose last build finished successfully")
    previous.add_argument("--packages-select-test-failures", action="store_true",
                          help="only packages whose last test run had failures or errors")
    previous.add_argument("--packages-skip-test-passed", action="store_true",
                          help="skip packages whose last test run passed")
    add("--packages-select", nargs="*", metavar="PKG_NAME", help="only these packages")
    add("--packages-skip", nargs="*", metavar="PKG_NAME", help="skip these packages")
    add("--packages-select-regex", nargs="*", metavar="PATTERN", help="only packages whose name matches a pattern")
    add("--packages-skip-regex", nargs="*", metavar="PATTERN", help="skip packages whose name matches a pattern")
    add("--packages-start", metavar="PKG_NAME", help="skip packages before this one in topological order")
    add("--packages-end", metavar="PKG_NAME", help="skip packages after this one in topological order")



class AppendToCommandLine(argparse._AppendAction):
    """``append``, except that the first value given on the command line replaces a default list from
    roc.toml or colcon's defaults instead of adding to it (the command line wins, as in colcon)."""

    def __call__(self, parser, namespace, values, option_string=None):
        marker = f"_given_{self.dest}"
        if not getattr(namespace, marker, False):
            setattr(namespace, self.dest, [])
            setattr(namespace, marker, True)
        super().__call__(parser, namespace, values, option_string)


def add_base_arguments(parser: argparse.ArgumentParser) -> None:
    """Where the build directories and install prefixes are (build, cache, env)."""
    parser.add_argument("--build-base", default="build",
                        help="base directory of the build directories (default: build)")
    parser.add_argument("--install-base", default="install",
                        help="base directory of the install prefixes (default: install)")
    parser.add_argument("--merge-install", action="store_true", help="install all packages into one prefix")


def add_layout_arguments(parser: argparse.ArgumentParser) -> None:
    """The options that decide where packages go and what their fingerprints are (build and cache)."""
    add = parser.add_argument
    add("--metas", nargs="*", metavar="PATH",
        help="colcon metadata files, or directories holding a colcon.meta (default: ./colcon.meta)")
    add("--ignore-user-meta", action="store_true", help="ignore the *.meta files in ~/.colcon/metadata")
    add_base_arguments(parser)
    add("--symlink-install", action="store_true", help="symlink installed files to the sources where possible")
    add("--cmake-args", action=AppendToCommandLine, default=[], metavar="ARG",
        help="arguments for CMake (values may start with '-')")
    add("--ament-cmake-args", action=AppendToCommandLine, default=[], metavar="ARG",
        help="arguments for ament_cmake packages")


def rewrite_passthrough(argv: list[str], known_options: set[str]) -> list[str]:
    """``--cmake-args -DA=1 -DB=2 --foo`` -> ``--cmake-args=-DA=1 --cmake-args=-DB=2 --foo``: values
    run until the next roc option (a value that is also a roc option is written with a leading space)."""
    result: list[str] = []
    current = None
    for token in argv:
        if token in PASSTHROUGH_OPTIONS:
            current = token
            continue
        if current and token.split("=", 1)[0] not in known_options:
            result.append(f"{current}={token.lstrip(' ')}")
            continue
        current = None
        result.append(token)
    return result


def values_source(args: argparse.Namespace, positional: str) -> tuple[str | None, str]:
    """The YAML values of a request or goal and where they come from: standard input with ``--stdin``
    (read to its end, as ros2 does), else the ``positional`` argument."""
    if getattr(args, "stdin", False):
        import sys

        return sys.stdin.read(), "standard input"
    return getattr(args, positional), positional


DEFAULT_TRUNCATE_LENGTH = 128  # ros2's: arrays, bytes and strings are cut after this many elements


def add_message_display_arguments(parser: argparse.ArgumentParser) -> None:
    """How ``echo`` verbs print a message's fields, with ros2's options."""
    parser.add_argument("--full-length", "-f", action="store_true",
                        help="do not truncate arrays, bytes and strings")
    parser.add_argument("--truncate-length", "-l", type=int, default=DEFAULT_TRUNCATE_LENGTH, metavar="N",
                        help="truncate arrays, bytes and strings after N elements "
                             f"(default: {DEFAULT_TRUNCATE_LENGTH})")
    parser.add_argument("--no-arr", action="store_true", help="do not print array fields")
    parser.add_argument("--no-str", action="store_true", help="do not print string fields")
    parser.add_argument("--flow-style", action="store_true", help="print lists inline (not with --csv)")


def add_graph_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of every verb that queries the ROS graph."""
    add_format_argument(parser)
    add_discovery_arguments(parser)


def add_discovery_arguments(parser: argparse.ArgumentParser) -> None:
    """How a graph verb reaches the graph: through the roc daemon, or discovering it itself."""
    parser.add_argument("--no-daemon", action="store_true", help="do not use (or start) the roc daemon")
    parser.add_argument("--spin-time", type=float, metavar="SECONDS",
                        help="without the daemon: how long at most to discover the graph (discovery ends "
                             "sooner, once every participant of this host has been heard and the graph is "
                             "quiet); for topic streams, also how long a topic's publishers may take to "
                             "appear (default: 3.5, one DDS announcement period, and up to 3 s more while "
                             "the graph is known to be incomplete)")


QOS_PROFILES = ("unknown", "default", "system_default", "sensor_data", "services_default", "parameters",
                "parameter_events", "action_status_default", "best_available")
QOS_POLICIES = {
    "history": ("system_default", "keep_last", "keep_all", "unknown"),
    "reliability": ("system_default", "reliable", "best_effort", "unknown", "best_available"),
    "durability": ("system_default", "transient_local", "volatile", "unknown", "best_available"),
    "liveliness": ("system_default", "automatic", "manual_by_topic", "unknown", "best_available"),
}


def add_qos_arguments(parser: argparse.ArgumentParser, default_profile: str, verb: str) -> None:
    """ros2's QoS options of ``topic echo`` / ``topic pub``; reliability and durability not given follow
    the topic's publishers (echo)."""
    parser.add_argument("--qos-profile", choices=QOS_PROFILES, default=default_profile,
                        help=f"QoS preset profile to {verb} with (default: {default_profile})")
    parser.add_argument("--qos-depth", type=int, metavar="N", help="queue size (overrides the profile's)")
    for policy, choices in QOS_POLICIES.items():
        parser.add_argument(f"--qos-{policy}", choices=choices, help=f"{policy} (overrides the profile's)")
    parser.add_argument("--qos-liveliness-lease-duration-seconds", type=float, metavar="SECONDS",
                        help="liveliness lease duration (overrides the profile's)")


def qos_options(args: argparse.Namespace) -> dict:
    """The QoS options as roc.ros.dataplane.qos_profile takes them."""
    return {"profile": args.qos_profile, "depth": args.qos_depth,
            "liveliness_lease_seconds": args.qos_liveliness_lease_duration_seconds,
            **{policy: getattr(args, f"qos_{policy}") for policy in QOS_POLICIES}}


def add_content_filter_arguments(parser: argparse.ArgumentParser) -> None:
    """ros2's ``--content-filter`` of ``topic echo``, ``hz`` and ``bw`` (ros2/ros2cli#1213)."""
    parser.add_argument("--content-filter", dest="content_filter_expr", metavar="EXPR",
                        help="only messages that pass this DDS content filter expression, e.g. \"data LIKE "
                             "'%%hello%%'\" or \"position.x > %%0\": evaluated by the middleware where it "
                             "can (the publishers then send nothing else), else by roc")
    parser.add_argument("--content-filter-params", nargs="*", default=[], metavar="PARAM",
                        help="the values of %%0, %%1, ... in --content-filter (a bare word is a string)")


def content_filter_options(args: argparse.Namespace) -> dict | None:
    """The ``content_filter`` of a stream request, its syntax checked here (a usage error before any
    subscription); ROC_MIDDLEWARE_CONTENT_FILTER=0 asks roc to filter instead of the middleware."""
    import os

    from roc.errors import UsageError
    from roc.ros.content_filter import ContentFilter

    if args.content_filter_expr is None:
        if args.content_filter_params:
            raise UsageError("--content-filter-params needs --content-filter")
        return None
    ContentFilter(args.content_filter_expr, args.content_filter_params)
    return {"expression": args.content_filter_expr, "parameters": args.content_filter_params,
            "middleware": os.environ.get("ROC_MIDDLEWARE_CONTENT_FILTER") != "0"}
