"""A Dask worker that builds roc packages: ``dask worker SCHEDULER --preload roc.cluster.worker
[--roc-root DIR]`` (what ``roc work worker`` runs), or any worker whose Dask configuration names the
preload (``distributed.worker.preload``, as ``dask ssh``, dask-jobqueue and dask-kubernetes start them).

The preload gives the worker its work root and advertises, as Dask resources, how many packages it
builds at once (``roc-build``, 1 unless ``--resources roc-build=N`` says otherwise) and its toolchain
fingerprint (``roc-toolchain-<digest>``, as many units), so that the scheduler gives a client's task
only to a worker with the client's toolchain.
"""

from __future__ import annotations

import logging
from pathlib import Path

import click

from roc.cluster.toolchain import BUILD_RESOURCE, machine_fingerprint, resource_name
from roc.cluster.workroot import WorkRoot

logger = logging.getLogger("distributed.worker")


@click.command()
@click.option("--roc-root", type=click.Path(file_okay=False),
              help="the folder this worker builds in (a workspace per task below it; default: roc/ in the "
                   "worker's own local directory, which Dask removes when the worker stops)")
def dask_setup(worker, roc_root: str | None) -> None:
    root = Path(roc_root).absolute() if roc_root else Path(worker.local_directory) / "roc"
    root.mkdir(parents=True, exist_ok=True)
    worker.roc_work_root = WorkRoot(root)
    state = worker.state
    slots = state.total_resources.get(BUILD_RESOURCE, 1)
    digest = machine_fingerprint(root)
    for name in (BUILD_RESOURCE, resource_name(digest)):
        state.total_resources[name] = slots
        state.available_resources[name] = slots
    # Dask samples the worker's threads every 10 ms for its dashboard's profile: a build's threads only
    # wait on their commands, and the sampling made a one-worker build of 100 packages 2 to 6 % slower.
    for callback in ("profile", "profile-cycle"):
        worker.periodic_callbacks.pop(callback, None)
    logger.info("roc: building in %s, %g package(s) at once, toolchain %s", root, slots, digest)
