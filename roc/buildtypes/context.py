"""What a build-type handler needs to build one package."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from roc.workspace.package import Package


@dataclass(frozen=True)
class BuildOptions:
    """The ``roc work build`` options that shape how packages are built."""

    build_base: Path
    install_base: Path
    merge_install: bool = False
    symlink_install: bool = False
    cmake_args: tuple[str, ...] = ()
    ament_cmake_args: tuple[str, ...] = ()
    cmake_target: str | None = None
    cmake_target_skip_unavailable: bool = False
    cmake_clean_cache: bool = False
    cmake_clean_first: bool = False
    cmake_force_configure: bool = False
    jobs: int = 2  # the global budget, shared through the make jobserver
    jobs_per_package: int = 2  # for build tools that cannot join the jobserver (ninja): an equal share
    # Per-package additions (roc.toml [package.NAME], colcon.meta), appended to the common arguments.
    package_cmake_args: dict[str, tuple[str, ...]] = field(default_factory=dict)
    package_ament_cmake_args: dict[str, tuple[str, ...]] = field(default_factory=dict)
    force: bool = False  # rebuild even when up to date
    use_state: bool = True  # read and write fingerprints (--no-cache turns it off)

    def cmake_args_for(self, package: str) -> tuple[str, ...]:
        return self.cmake_args + self.package_cmake_args.get(package, ())

    def ament_cmake_args_for(self, package: str) -> tuple[str, ...]:
        return self.ament_cmake_args + self.package_ament_cmake_args.get(package, ())

    def builds_tests(self, package: str) -> bool:
        """Whether the package's CMake arguments leave ``BUILD_TESTING`` on (ament_cmake's default;
        ``-DBUILD_TESTING=OFF`` or another of CMake's false values turns it off)."""
        value = "ON"
        for arg in self.cmake_args_for(package):
            name, _, given = arg.partition("=")
            if name in ("-DBUILD_TESTING", "-DBUILD_TESTING:BOOL"):
                value = given.upper()
        false = ("", "0", "OFF", "NO", "FALSE", "N", "IGNORE", "NOTFOUND")
        return value not in false and not value.endswith("-NOTFOUND")

    def partial(self) -> bool:
        """Builds that do not leave a complete, reusable install (never recorded as up to date)."""
        return bool(self.cmake_target)

    def always_rebuild(self) -> bool:
        return self.force or self.cmake_clean_cache or self.cmake_clean_first or self.cmake_force_configure


@dataclass
class PackageJob:
    """One package's build as a build type runs it: where its source, build directory and install
    prefix are, and the environment, jobserver and CMake arguments roc gives it."""

    package: Package
    source: Path  # absolute package directory
    build_dir: Path
    prefix: Path  # the package's install prefix (the install base itself when merged)
    env: dict[str, str] = field(default_factory=dict)
    make_flags: str = ""  # MAKEFLAGS for make-based builds (jobserver client flags)
    pass_fds: tuple[int, ...] = ()
    cmake_args: list[str] = field(default_factory=list)  # roc's own, after the user's (the idl task's ROC_IDL_DIR)
