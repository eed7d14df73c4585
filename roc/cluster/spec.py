"""What travels between the client and a worker: the description of one package's build or test
(``PackageWork``) and what the worker did (``WorkResult``). Plain data; artefacts (installed files,
test result files) never travel here, only through the remote cache."""

from __future__ import annotations

from dataclasses import dataclass, field

from roc.engine.events import Event


@dataclass(frozen=True)
class PackageWork:
    package: dict  # roc.workspace.package.Package.to_dict(), without its manifest
    dependencies: list[tuple[dict, str]]  # each workspace dependency, in build order, and its remote key
    key: str  # the package's remote key, as the client computed it
    portable: dict  # what that key is made of (to say why a worker's differs)
    sources: bytes  # the package's source files (roc.cluster.files), as its fingerprint counts them
    options: dict  # the roc.buildtypes.context.BuildOptions fields that shape a build (no paths)
    cache_url: str  # the remote cache, without credentials (a worker uses its own)
    cache_timeout: float
    toolchain: str  # the client's toolchain fingerprint (roc.cluster.toolchain)
    toolchain_parts: dict
    compiler_cache: str | None = None  # ccache or sccache, as the client's --compiler-cache
    force: bool = False  # build even when the cache has it (--force)
    test: dict | None = None  # for a test task: the roc.testing.runner.TestOptions fields (no paths)

    @property
    def name(self) -> str:
        return self.package["name"]


@dataclass(frozen=True)
class WorkResult:
    ok: bool
    key: str  # the package's remote key (what a build uploaded is under it)
    worker: str
    duration: float  # seconds on the worker, restores and upload included
    events: list[Event] = field(default_factory=list)  # the commands, their output and warnings, in order
    reason: str = ""  # why it failed (or was refused)
    refused: bool = False  # the worker's toolchain or remote key differs: it built nothing
    bound: str | None = None  # built, but this installed file holds the worker's path: not restorable elsewhere
    passed: bool | None = None  # a test task: whether every test passed
    results: str | None = None  # a test task: the SHA-256 of its result files' archive in the remote cache
