"""``roc work build``: build the workspace, a drop-in for ``colcon build``."""

from __future__ import annotations

import argparse
import os
import sys
import threading
import zlib
from functools import partial
from pathlib import Path

from roc.cli.options import add_layout_arguments, add_selection_arguments
from roc.errors import EXIT_FAILURE, EXIT_INTERRUPTED, UsageError
from roc.handlers import add_event_handlers_argument, handler_switches, output_handlers

NOT_SUPPORTED_OPTIONS = ("test_result_base", "catkin_cmake_args",
                         "catkin_skip_building_tests")
DURATIONS_FILE = "roc_durations.json"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add = parser.add_argument
    add("packages", nargs="*", metavar="PKG_NAME", help="shorthand for --packages-up-to PKG_NAME...")
    add_layout_arguments(parser)
    add("--log-base", default="log", help="base directory of the logs, or /dev/null for none (default: log)")
    add("--continue-on-error", action="store_true",
        help="keep building packages that do not depend on a failed one (default: stop at the first failure)")
    add("--executor", choices=("parallel", "sequential"), default="parallel", help="run packages in parallel "
        "(default) or one at a time")
    add("--parallel-workers", type=int, metavar="NUMBER", default=os.cpu_count() or 1,
        help="packages built at once, 0 for no limit (default: the number of CPUs)")
    add("-j", "--jobs", type=int, metavar="N",
        help="compiler jobs of all packages together (default: -j of MAKEFLAGS, else the number of CPUs)")
    add_event_handlers_argument(parser)
    add("--output", choices=("text", "json"), default="text", help="json: one JSON event per line on stdout")
    add("--tui", action="store_true", help="show the build in roc's terminal user interface: a row per package with "
        "its state, elapsed time and step; Enter shows a failed package's stderr (see roc tui)")
    add("--allow-overriding", action="extend", nargs="+", default=[], metavar="PKG_NAME",
        help="build these packages without the warning that an underlay workspace has them too")
    add("--force", action="store_true", help="rebuild the selected packages even when they are up to date")
    add("--explain", action="store_true",
        help="build nothing: print each selected package, in build order, and why it would be built")
    add("--no-cache", action="store_true",
        help="neither skip up-to-date packages nor record fingerprints for the next build")
    remote = parser.add_argument_group("remote build cache (docs/caching.md)")
    remote.add_argument("--remote-cache", metavar="URL",
                        help="restore packages built elsewhere from this cache (http(s):// WebDAV or "
                             "bazel-remote, s3://BUCKET/PREFIX) instead of building them (default: "
                             "$ROC_REMOTE_CACHE)")
    remote.add_argument("--remote-cache-mode", choices=("read", "read-write", "off"),
                        help="read: restore only (default); read-write: also upload what is built (CI); "
                             "off: do not use it (default: $ROC_REMOTE_CACHE_MODE, else read)")
    remote.add_argument("--remote-cache-timeout", type=float, metavar="SECONDS",
                        help="give up on a server that does not answer within this time, and build "
                             "locally (default: 10)")
    from roc.cluster.settings import add_cluster_argument

    add_cluster_argument(remote, "build the packages the remote cache misses")
    remote.add_argument("--compiler-cache", choices=("ccache", "sccache", "none"),
                        help="compile CMake packages through ccache or sccache (on the remote cache's server "
                             "too, when one is set)")
    remote.add_argument("--compiler-cache-dir", metavar="DIR",
                        help="the compiler cache's local directory (default: the tool's own)")
    cmake = parser.add_argument_group("cmake and ament_cmake packages")
    cmake.add_argument("--cmake-target", help="build this target instead of the default one (no install)")
    cmake.add_argument("--cmake-target-skip-unavailable", action="store_true",
                       help="skip packages that do not have the --cmake-target")
    cmake.add_argument("--cmake-clean-cache", action="store_true", help="remove the CMake cache first")
    cmake.add_argument("--cmake-clean-first", action="store_true", help="build target 'clean' first")
    cmake.add_argument("--cmake-force-configure", action="store_true", help="always run the CMake configure step")
    unsupported = parser.add_argument_group("colcon options roc does not support yet (rejected if used)")
    unsupported.add_argument("--test-result-base", help=argparse.SUPPRESS)
    unsupported.add_argument("--catkin-cmake-args", nargs="*", help=argparse.SUPPRESS)
    unsupported.add_argument("--catkin-skip-building-tests", action="store_true", default=None,
                             help=argparse.SUPPRESS)
    add_selection_arguments(parser)


def build_options(args: argparse.Namespace, root: Path, **extra):
    """BuildOptions from the command line and the configuration's per-package settings."""
    from roc.buildtypes.context import BuildOptions

    config = getattr(args, "configuration", None)
    per_package = {key: {name: tuple(value) for name, value in config.package_values(key).items()}
                   if config else {} for key in ("cmake-args", "ament-cmake-args")}
    return BuildOptions(
        build_base=(root / args.build_base).absolute(), install_base=(root / args.install_base).absolute(),
        merge_install=args.merge_install, symlink_install=args.symlink_install,
        cmake_args=tuple(args.cmake_args), ament_cmake_args=tuple(args.ament_cmake_args),
        package_cmake_args=per_package["cmake-args"], package_ament_cmake_args=per_package["ament-cmake-args"],
        **extra,
    )


def skip_unbuildable_packages(workspace) -> None:
    """Packages of a build type roc has no handler for are skipped with a warning, as colcon does."""
    from roc.buildtypes import BUILD_TYPES
    from roc.messages import warn

    for package in workspace.selected_in_order():
        if package.type not in BUILD_TYPES:
            warn(f"{package.path}: no way to build '{package.name}' of type '{package.type}' "
                 f"(roc builds {', '.join(sorted(BUILD_TYPES))}); skipped")
            workspace.selected.discard(package.name)


def skip_configured_packages(args: argparse.Namespace, workspace) -> None:
    """Packages with ``skip = true`` in roc.toml are not built (they stay in the graph)."""
    config = getattr(args, "configuration", None)
    if config:
        workspace.selected -= {name for name, skip in config.package_values("skip").items() if skip}


def warn_about_overrides(args: argparse.Namespace, workspace, install_base: Path) -> None:
    """colcon-override-check's warning: a selected package shadows one that underlay packages use."""
    from roc.messages import warn
    from roc.workspace.underlay import overridden_packages, override_warning

    for name in args.allow_overriding:
        if name not in workspace.by_name:
            warn(f"--allow-overriding: ignoring unknown package '{name}'")
    overridden = overridden_packages(workspace.selected, install_base, args.allow_overriding, os.environ)
    if overridden:
        warn(override_warning(overridden))


def warn_about_missing_dependencies(workspace, options) -> None:
    """Dependencies of the selected packages that neither the workspace nor an underlay has (colcon
    builds on silently): a warning for each build or run dependency (a typo, most likely, or a system
    dependency), with the closest known name that is not a package depending on it; and one quieter
    note for the test dependencies of the packages that build their tests, which only the tests need.
    Each is said once until a manifest of the workspace changes (roc.builder.state.not_said_yet)."""
    from roc.builder.environment import base_environment
    from roc.builder.state import not_said_yet
    from roc.messages import PACKAGE_NAME_CUTOFF, did_you_mean, warn
    from roc.render import print_text
    from roc.workspace.underlay import missing_dependencies, underlay_packages

    known = set(workspace.by_name) | set(underlay_packages(base_environment()))
    selected = [workspace.by_name[name] for name in sorted(workspace.selected)]
    needed = missing_dependencies(selected, known, ("build", "run"))
    warnings = []
    for name, users in needed.items():
        hint = did_you_mean(name, known - set(users), count=1, cutoff=PACKAGE_NAME_CUTOFF) or (
            "a typo? (a system dependency that rosdep installs is fine)")
        warnings.append(f"'{name}', a dependency of {', '.join(users)}, is in neither the workspace nor an underlay; "
                        f"{hint}")
    testing = [package for package in selected if options.builds_tests(package.name)]
    tested = {name: users for name, users in missing_dependencies(testing, known, ("test",)).items()
              if name not in needed}
    notes = []
    if tested:
        count = f"{len(tested)} test {'dependency' if len(tested) == 1 else 'dependencies'}"
        notes.append(f"{count} in neither the workspace nor an underlay, needed "
                     "only to build and run the tests (--cmake-args -DBUILD_TESTING=OFF builds without them): "
                     + ", ".join(f"{name} (of {', '.join(users)})" for name, users in tested.items()))
    said = not_said_yet(options.build_base, _manifests_stamp(workspace),
                        [f"warning: {text}" for text in warnings] + [f"note: {text}" for text in notes])
    for text in warnings:
        if f"warning: {text}" in said:
            warn(text)
    for text in notes:
        if f"note: {text}" in said:
            print_text(f"roc: note: {text}\n", sys.stderr)


def _manifests_stamp(workspace) -> str:
    """What changes when a manifest of the workspace changes: the time and size of each package.xml."""
    stamps, root = [], str(workspace.root)
    for package in workspace.ordered:
        try:
            info = os.stat(os.path.join(root, package.path_text, "package.xml"))
        except OSError:
            continue
        stamps.append((package.name, info.st_mtime_ns, info.st_size))
    return f"{zlib.crc32(repr(stamps).encode()):08x}"


def failure_note(workspace, key: str, stderr: str) -> str:
    """What the console adds to a failed package's line: how to go on, when roc knows the cause."""
    from roc import distribution
    from roc.builder.failure_hints import failure_hint

    package = workspace.by_name.get(key)  # None for a task of another kind (idl:pkg)
    found = distribution.detected() if package else None
    hint = failure_hint(stderr, package, workspace.by_name, found[0] if found else None) if package else ""
    return f": {hint}" if hint else ""


def remote_cache(args: argparse.Namespace, workspace, options):
    """The run's RemoteCache, or None when the remote cache is off or not configured. The environment
    wins over roc.toml; the command line over both. (``roc work test`` has only ``--remote-cache``.)"""
    if not (args.remote_cache or os.environ.get("ROC_REMOTE_CACHE")):
        return None  # (nothing of the remote cache imported: a no-op build stays fast)
    from roc.remote_cache.settings import MODE_VARIABLE, URL_VARIABLE, remote_settings

    config = getattr(args, "configuration", None)
    given = {}
    for dest, variable in (("remote_cache", URL_VARIABLE), ("remote_cache_mode", MODE_VARIABLE)):
        from_file = config is not None and config.from_configuration(args, dest)
        given[dest] = None if from_file and os.environ.get(variable) else getattr(args, dest, None)
    settings = remote_settings(given["remote_cache"], given["remote_cache_mode"],
                               getattr(args, "remote_cache_timeout", None))
    if settings is None:
        return None
    if settings.url.startswith("s3://"):
        import importlib.util

        if importlib.util.find_spec("boto3") is None:
            raise UsageError("--remote-cache s3://...: boto3 is not installed; pip install 'roc[s3]' "
                             "(or boto3) into roc's environment")
    from roc.builder.artefact import Places
    from roc.remote_cache.cache import RemoteCache

    return RemoteCache(settings, Places(workspace.root, options.build_base, options.install_base),
                       options.merge_install)


def _explain(args: argparse.Namespace, workspace, options, remote) -> int:
    from roc.builder.uptodate import explain
    from roc.engine.events import task_key
    from roc.render import print_json, print_lines

    explained = explain(workspace, options, remote)
    if args.output == "json":
        print_json([{"package": name, "kind": kind, "reasons": reasons} for kind, name, reasons in explained])
    else:
        print_lines([f"{task_key(kind, name)}: {'; '.join(reasons) or 'up to date'}"
                     for kind, name, reasons in explained])
    return 0


def _check_supported(args: argparse.Namespace) -> None:
    for option in NOT_SUPPORTED_OPTIONS:
        if getattr(args, option) not in (None, False):
            raise UsageError(f"--{option.replace('_', '-')} is not supported by roc yet")


def run(args: argparse.Namespace) -> int:
    if args.tui and not args.explain:
        from roc.tui import require_terminal

        require_terminal("--tui")
    workspace, options, switches, remote = _prepare(args)
    if args.explain:
        return _explain(args, workspace, options, remote)
    warn_about_overrides(args, workspace, options.install_base)
    warn_about_missing_dependencies(workspace, options)
    build = partial(_locked_build, args, workspace, options, switches, remote)
    if args.tui:
        from roc.tui.app import run_build_app

        return run_build_app(build, verb="build")
    return build()


def build_runner(packages: list[str]):
    """A build of ``packages`` (every package when empty) of the workspace around the current
    directory, with the default options: (handlers, stop) -> exit code, for a build started in roc tui."""
    from roc.cli.commands import build_parser

    args = build_parser(["work", "build"]).parse_args(["work", "build", *packages])
    args.configuration = None
    workspace, options, switches, remote = _prepare(args)
    return partial(_locked_build, args, workspace, options, switches, remote)


def _prepare(args: argparse.Namespace):
    """The workspace, the build options and the output switches of a build, from its arguments."""
    from roc.engine.jobserver import jobs_from_makeflags
    from roc.workspace.load import load_workspace

    _check_supported(args)
    switches = handler_switches(args.event_handlers)
    if args.packages:
        args.packages_up_to = [*(args.packages_up_to or []), *args.packages]
    if args.parallel_workers < 0:
        raise UsageError("--parallel-workers must be 0 (no limit) or more")
    if args.jobs is not None and args.jobs < 1:
        raise UsageError("-j/--jobs must be 1 or more")
    workspace = load_workspace(args)
    skip_configured_packages(args, workspace)
    skip_unbuildable_packages(workspace)
    jobs = args.jobs or jobs_from_makeflags(os.environ.get("MAKEFLAGS", "")) or os.cpu_count() or 1
    workers = 1 if args.executor == "sequential" else args.parallel_workers or len(workspace.selected) or 1
    options = build_options(
        args, workspace.root, cmake_target=args.cmake_target,
        cmake_target_skip_unavailable=args.cmake_target_skip_unavailable,
        cmake_clean_cache=args.cmake_clean_cache, cmake_clean_first=args.cmake_clean_first,
        cmake_force_configure=args.cmake_force_configure, jobs=jobs, jobs_per_package=max(1, jobs // workers),
        force=args.force,
        use_state=not args.no_cache,
    )
    from roc.builder.layout import check_distribution

    check_distribution(options.build_base, options.install_base)  # --explain too: what the build would say
    remote = remote_cache(args, workspace, options)  # bad settings: a usage error before anything is written
    from roc.cluster.settings import cluster_address

    args.cluster_address = None if args.explain else cluster_address(args, remote)
    return workspace, options, switches, remote


def _locked_build(args, workspace, options, switches: dict[str, bool], remote, extra_handlers: list | None = None,
                  stop: threading.Event | None = None) -> int:
    """Build under the build base's lock. ``extra_handlers`` (roc tui's board and summary) replace the
    console; ``stop`` ends the run as Ctrl+C does."""
    from roc.builder.layout import prepare_build_base, prepare_install_base, record_distribution
    from roc.builder.lock import build_lock

    compiler = None
    if args.compiler_cache not in (None, "none"):
        from roc.builder.compiler_cache import compiler_cache

        compiler = compiler_cache(args.compiler_cache, args.compiler_cache_dir, workspace.root, options.build_base,
                                  remote.settings if remote else None)
    cluster = _connect_cluster(args, workspace, options, remote)
    try:
        with build_lock(options.build_base):
            prepare_build_base(options.build_base)
            record_distribution(options.build_base)
            prepare_install_base(options.install_base, args.merge_install)
            return _build(args, workspace, options, switches, remote, compiler, extra_handlers, stop, cluster)
    finally:
        if cluster is not None:
            cluster.cluster.close()


def _connect_cluster(args, workspace, options, remote):
    """The run's ClusterBuilds with --cluster, when anything is to be built (a no-op build never loads
    Dask). When the remote cache lacks a package, the scheduler unreachable or no worker fitting is a
    one-line error before anything is done; when it has them all, they are restored without the
    scheduler (connected only if a restore misses after all)."""
    if not args.cluster_address:
        return None
    from roc.builder.uptodate import anything_the_cache_lacks, anything_to_build

    if not anything_to_build(workspace, options):
        return None
    from roc.cluster.client import OnDemand, connect
    from roc.cluster.remote_build import ClusterBuilds

    cluster = OnDemand(partial(connect, args.cluster_address, options.install_base))
    if anything_the_cache_lacks(workspace, options, remote):
        cluster.connect()
    compiler = None if args.compiler_cache == "none" else args.compiler_cache
    return ClusterBuilds(cluster, workspace, remote, compiler)


def _build(args, workspace, options, switches: dict[str, bool], remote, compiler,
           extra_handlers: list | None = None, stop: threading.Event | None = None, cluster=None) -> int:
    from roc.builder.layout import refresh_install_scripts
    from roc.builder.plan import plan_build
    from roc.engine.executor import execute
    from roc.engine.jobserver import Jobserver
    from roc.engine.store import DurationStore

    workers = 1 if args.executor == "sequential" else args.parallel_workers
    durations = DurationStore(options.build_base / DURATIONS_FILE)
    jobserver = Jobserver(options.jobs)
    handlers = [*output_handlers(args, switches, workspace.root, options.build_base, console=extra_handlers is None,
                                 failed_note=partial(failure_note, workspace)),
                durations, *(extra_handlers or [])]
    try:
        tasks = plan_build(workspace, options, jobserver, durations.durations, remote, compiler, cluster)
        limit = workers if cluster is None else cluster.cluster.task_limit(workers)
        result = execute(tasks, handlers, limit, continue_on_error=args.continue_on_error, stop=stop)
    finally:
        jobserver.close()
        statistics = compiler.finish() if compiler is not None else None
        if statistics and args.output != "json":
            print(statistics, flush=True)
        for handler in handlers:  # e.g. the terminal's live line, when the run ended by an error
            getattr(handler, "close", lambda: None)()
    durations.save()
    refresh_install_scripts(options.install_base, args.merge_install, options.build_base)
    if result.interrupted:
        return EXIT_INTERRUPTED
    return 0 if result.ok else EXIT_FAILURE
