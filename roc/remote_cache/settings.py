"""Where the remote build cache is and what a build may do with it: ``--remote-cache URL`` (or
``remote-cache`` in roc.toml, or ``$ROC_REMOTE_CACHE``), ``--remote-cache-mode`` (``read``, the default
for a developer; ``read-write`` for CI; ``off``) and ``--remote-cache-timeout``."""

from __future__ import annotations

import os
from dataclasses import dataclass
from urllib.parse import urlsplit, urlunsplit

from roc.errors import UsageError

MODES = ("read", "read-write", "off")
SCHEMES = ("http", "https", "s3")
URL_VARIABLE = "ROC_REMOTE_CACHE"
MODE_VARIABLE = "ROC_REMOTE_CACHE_MODE"
DEFAULT_TIMEOUT = 10.0


@dataclass(frozen=True)
class RemoteSettings:
    url: str
    mode: str  # read or read-write (off: no settings at all)
    timeout: float  # seconds, for connecting and for each read

    @property
    def writes(self) -> bool:
        return self.mode == "read-write"

    @property
    def shown(self) -> str:
        return redact(self.url)


def redact(url: str) -> str:
    """The URL without credentials or query (what roc prints and logs)."""
    parts = urlsplit(url)
    host = parts.hostname or ""
    if parts.port:
        host += f":{parts.port}"
    return urlunsplit((parts.scheme, host, parts.path, "", ""))


def remote_settings(url: str | None, mode: str | None, timeout: float | None) -> RemoteSettings | None:
    """The settings from the given values, the environment filling what is None; None when the remote
    cache is off or no URL is set. A bad URL, mode or timeout is a usage error."""
    url = url or os.environ.get(URL_VARIABLE) or None
    mode = mode or os.environ.get(MODE_VARIABLE) or "read"
    if mode not in MODES:
        raise UsageError(f"--remote-cache-mode (or ${MODE_VARIABLE}): '{mode}' is not one of {', '.join(MODES)}")
    if mode == "off" or not url:
        return None
    parts = urlsplit(url)
    if parts.scheme not in SCHEMES or not parts.netloc:
        raise UsageError(f"--remote-cache: '{redact(url)}' is not an http://, https:// or s3://BUCKET URL")
    if timeout is not None and timeout <= 0:
        raise UsageError("--remote-cache-timeout must be more than 0 seconds")
    return RemoteSettings(url.rstrip("/"), mode, timeout or DEFAULT_TIMEOUT)
