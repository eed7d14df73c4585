"""Which Dask scheduler a build or test run uses: ``--cluster ADDRESS``, else ``$ROC_CLUSTER``, else
``cluster`` in roc.toml (the command line wins, then the environment, then the file, as for the
remote cache). Nothing of Dask is imported here."""

from __future__ import annotations

import argparse
import os
import re

from roc.errors import UsageError

VARIABLE = "ROC_CLUSTER"
SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")
_ADDRESS = re.compile(r"^(?:(?P<scheme>[a-z]+)://)?(?P<host>\[[0-9a-fA-F:]+\]|[^/:\s]+)(?::(?P<port>\d+))?/?$")


def add_cluster_argument(parser: argparse.ArgumentParser | argparse._ArgumentGroup, what: str) -> None:
    parser.add_argument("--cluster", metavar="ADDRESS",
                        help=f"{what} on the Dask cluster whose scheduler is at ADDRESS (tcp://HOST:8786, or "
                             "tls:// with Dask's TLS settings), their results through the remote cache, which "
                             "this needs (default: $ROC_CLUSTER; see docs/cluster.md)")


def cluster_address(args: argparse.Namespace, remote: object | None) -> str | None:
    """The scheduler's address, or None for no cluster. A malformed one, or one without a ``remote``
    cache, is a usage error."""
    config = getattr(args, "configuration", None)
    from_file = config is not None and config.from_configuration(args, "cluster")
    given = args.cluster
    if given is None or (from_file and os.environ.get(VARIABLE)):
        given = os.environ.get(VARIABLE) or given
    if not given:
        return None
    match = _ADDRESS.match(given.strip())
    if match is None or (match["scheme"] and match["scheme"] not in SCHEMES):
        raise UsageError(f"--cluster (or ${VARIABLE}): '{given}' is not a Dask scheduler address such as "
                         "tcp://HOST:8786 or tls://HOST:8786")
    if remote is None:
        raise UsageError("--cluster needs a remote cache (--remote-cache URL, or $ROC_REMOTE_CACHE): what the "
                         "workers do comes back through it")
    scheme = match["scheme"] or "tcp"
    return f"{scheme}://{match['host']}:{match['port'] or 8786}"
