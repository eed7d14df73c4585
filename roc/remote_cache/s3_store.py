"""The remote cache in an S3-compatible object store: ``s3://BUCKET/PREFIX``, through boto3.

The endpoint, region and credentials come from boto3's own chain (``AWS_ENDPOINT_URL`` or
``AWS_ENDPOINT_URL_S3`` for a MinIO, Ceph or other non-AWS server, ``AWS_ACCESS_KEY_ID``, the shared
credentials file, an instance role, ...). roc never reads or prints them. boto3 is an optional
dependency (``pip install 'roc[s3]'``).
"""

from __future__ import annotations

from pathlib import Path
from urllib.parse import urlsplit

from roc.errors import UsageError
from roc.remote_cache.store import StoreUnavailable

NOT_FOUND = ("404", "NoSuchKey", "NotFound")


class S3Store:
    def __init__(self, url: str, timeout: float):
        try:
            import boto3
            import botocore.config
            import botocore.exceptions
        except ImportError:
            raise UsageError("--remote-cache s3://...: boto3 is not installed; pip install 'roc[s3]' "
                             "(or boto3) into roc's environment") from None
        parts = urlsplit(url)
        self.bucket = parts.netloc
        self.prefix = parts.path.strip("/") + "/" if parts.path.strip("/") else ""
        config = botocore.config.Config(connect_timeout=timeout, read_timeout=timeout,
                                        retries={"max_attempts": 2, "mode": "standard"})
        self.client = boto3.session.Session().client("s3", config=config)
        self.errors = botocore.exceptions

    def _call(self, operation, **kwargs):
        """Run one client call; a missing object is None, every other failure StoreUnavailable."""
        errors = self.errors
        try:
            return operation(Bucket=self.bucket, **kwargs)
        except errors.ClientError as error:
            code = str(error.response.get("Error", {}).get("Code", ""))
            if code in NOT_FOUND:
                return None
            raise StoreUnavailable(f"the S3 server refused: {code or 'an error'}") from None
        except errors.NoCredentialsError:
            raise StoreUnavailable("no S3 credentials (set AWS_ACCESS_KEY_ID/AWS_SECRET_ACCESS_KEY or a "
                                   "profile)") from None
        except (errors.ConnectTimeoutError, errors.ReadTimeoutError):
            raise StoreUnavailable("no answer in time") from None
        except errors.EndpointConnectionError:
            raise StoreUnavailable("cannot connect") from None
        except errors.BotoCoreError as error:
            raise StoreUnavailable(type(error).__name__) from None

    def get(self, path: str, destination: Path) -> bool:
        response = self._call(self.client.get_object, Key=self.prefix + path)
        if response is None:
            return False
        try:
            with open(destination, "wb") as out:
                for chunk in response["Body"].iter_chunks(1 << 20):
                    out.write(chunk)
        except (self.errors.BotoCoreError, OSError) as error:
            raise StoreUnavailable(f"the download stopped ({type(error).__name__})") from None
        return True

    def put(self, path: str, source: Path) -> None:
        with open(source, "rb") as data:
            self._call(self.client.put_object, Key=self.prefix + path, Body=data)

    def exists(self, path: str) -> bool:
        return self._call(self.client.head_object, Key=self.prefix + path) is not None
