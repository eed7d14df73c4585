"""The remote build cache: built packages shared through a server teams already run (an HTTP/WebDAV
cache such as bazel-remote or nginx, or an S3-compatible object store), keyed by each package's
portable content key. See docs/caching.md."""
