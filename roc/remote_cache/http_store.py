"""The remote cache on an HTTP server with GET, PUT and HEAD under a base URL: bazel-remote's HTTP
cache (with ``--disable_http_ac_validation``: roc's ``ac/`` entries are not Bazel action results),
nginx with its DAV module, or any WebDAV server. A WebDAV server that refuses a PUT because the
folder is missing (409) gets the folders made with MKCOL, then the PUT again.

Credentials: a ``user:password@`` in the URL, else ``~/.netrc`` (requests reads it; ``$NETRC`` moves
it). They are never printed: errors name the status or the failure, never the URL's user part.
"""

from __future__ import annotations

from pathlib import Path
from urllib.parse import urlsplit, urlunsplit

import requests

from roc.remote_cache.store import StoreUnavailable

CHUNK = 1 << 20


class HttpStore:
    def __init__(self, url: str, timeout: float):
        self.base = url.rstrip("/") + "/"
        self.timeout = timeout
        self.session = requests.Session()  # keeps connections open; trust_env: netrc, proxies

    def _request(self, method: str, path: str, **kwargs) -> requests.Response:
        try:
            return self.session.request(method, self.base + path, timeout=self.timeout, **kwargs)
        except requests.Timeout:
            raise StoreUnavailable(f"no answer within {self.timeout:g} s") from None
        except requests.ConnectionError as error:
            refused = "refused" in str(error).lower()
            raise StoreUnavailable("connection refused" if refused else "cannot connect") from None
        except requests.RequestException as error:
            raise StoreUnavailable(type(error).__name__) from None

    @staticmethod
    def _failed(response: requests.Response, what: str) -> StoreUnavailable:
        access = " (check the credentials in the URL or ~/.netrc)" if response.status_code in (401, 403) else ""
        return StoreUnavailable(f"{what} answered HTTP {response.status_code}{access}")

    def get(self, path: str, destination: Path) -> bool:
        response = self._request("GET", path, stream=True)
        with response:
            if response.status_code == 404:
                return False
            if response.status_code != 200:
                raise self._failed(response, "GET")
            try:
                with open(destination, "wb") as out:
                    for chunk in response.iter_content(CHUNK):
                        out.write(chunk)
            except requests.RequestException:
                raise StoreUnavailable(f"the download stopped (no data within {self.timeout:g} s)") from None
        return True

    def put(self, path: str, source: Path) -> None:
        response = self._put(path, source)
        if response.status_code in (404, 405, 409):  # WebDAV: the parent collection does not exist
            self._make_folders(path)
            response = self._put(path, source)
        if response.status_code not in (200, 201, 204):
            raise self._failed(response, "PUT")

    def _put(self, path: str, source: Path) -> requests.Response:
        with open(source, "rb") as data:
            return self._request("PUT", path, data=data)

    def _make_folders(self, path: str) -> None:
        """MKCOL every folder from the base URL's path down to ``path``'s (an existing one answers 405)."""
        split = urlsplit(self.base + path)
        segments = split.path.strip("/").split("/")[:-1]
        for depth in range(1, len(segments) + 1):
            folder = urlunsplit((split.scheme, split.netloc, "/" + "/".join(segments[:depth]) + "/", "", ""))
            try:
                self.session.request("MKCOL", folder, timeout=self.timeout)
            except requests.RequestException as error:
                raise StoreUnavailable(f"MKCOL failed ({type(error).__name__})") from None

    def exists(self, path: str) -> bool:
        response = self._request("HEAD", path)
        if response.status_code == 404:
            return False
        if response.status_code != 200:
            raise self._failed(response, "HEAD")
        return True
