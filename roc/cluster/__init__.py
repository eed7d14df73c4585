"""Builds and tests on a Dask cluster (``roc work build --cluster``, ``roc work test --cluster``,
``roc work worker``): each package a Dask task, its artefacts through the remote cache. See
docs/cluster.md. Only ``settings`` is imported without ``--cluster``; the rest loads Dask."""
