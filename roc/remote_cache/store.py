"""A remote store of blobs by path (``ac/<key>``, ``cas/<sha256>``): what the remote cache needs of a
server, implemented by http_store (HTTP/WebDAV) and s3_store (S3-compatible)."""

from __future__ import annotations

from pathlib import Path
from typing import Protocol


class StoreUnavailable(Exception):
    """The server could not be used: unreachable, too slow, refusing access, or failing. The message
    is short and holds no credentials."""


class Store(Protocol):
    def get(self, path: str, destination: Path) -> bool:
        """Write the blob at ``path`` to ``destination``; False when there is none."""
        ...

    def put(self, path: str, source: Path) -> None:
        """Store ``source`` at ``path`` (replacing what is there)."""
        ...

    def exists(self, path: str) -> bool:
        ...

