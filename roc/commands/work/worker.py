"""``roc work worker SCHEDULER --root DIR``: a Dask worker that builds and tests packages for ``roc work
build --cluster`` and ``roc work test --cluster``.

It runs Dask's own worker (``python -m distributed.cli.dask_worker``, the program behind ``dask
worker``) with roc's preload (roc.cluster.worker), so a worker started by ``dask worker SCHEDULER
--preload roc.cluster.worker --roc-root DIR`` (by ``dask ssh``, dask-jobqueue, dask-kubernetes) is the
same worker. See docs/cluster.md.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import sys

from roc.errors import UsageError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add = parser.add_argument
    add("scheduler", metavar="SCHEDULER", help="the Dask scheduler's address, e.g. tcp://build-scheduler:8786 "
        "(tls:// with Dask's TLS options in --dask-options)")
    add("--root", required=True, metavar="DIR", help="the folder the worker builds in (a workspace of its own for "
        "each package it builds at once, kept from task to task): give it the room of a workspace's build")
    add("--name", help="the worker's name, as clients show it (default: Dask's, the worker's address)")
    add("--builds", type=int, default=1, metavar="N",
        help="packages built or tested at once (default 1: each gets every core the worker may use)")
    add("--dask-options", nargs=argparse.REMAINDER, default=[], metavar="OPTION",
        help="the rest of the command line goes to Dask's worker, e.g. --dask-options --host 10.0.0.5 "
             "--tls-ca-file ca.pem (see dask worker --help)")


def worker_command(args: argparse.Namespace) -> list[str]:
    """Dask's worker with roc's preload, as ``dask worker`` would be run."""
    command = [sys.executable, "-m", "distributed.cli.dask_worker", args.scheduler,
               "--nthreads", str(args.builds), "--resources", f"roc-build={args.builds}",
               "--preload", "roc.cluster.worker", "--roc-root", os.path.abspath(args.root)]
    if args.name:
        command += ["--name", args.name]
    return command + list(args.dask_options)


def run(args: argparse.Namespace) -> int:
    if args.builds < 1:
        raise UsageError("--builds must be 1 or more")
    if importlib.util.find_spec("distributed") is None:
        raise UsageError("roc work worker needs Dask's distributed: pip install 'roc[cluster]' (or distributed) "
                         "into roc's environment")
    command = worker_command(args)
    os.execv(command[0], command)  # Dask's worker from here on: its signals, its exit code
    return 0
