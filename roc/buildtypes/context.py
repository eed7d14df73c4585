"""What a build-type handler needs to build one package."""

from __future__ import annotations

from pathlib import Path

from roc.workspace.package import Package


class BuildOptions:
    """The ``roc work build`` options that shape how packages are built; never changed once made.

    Plain classes here, not dataclasses: importing dataclasses costs every build's start-up 8 ms."""

    __slots__ = ("build_base", "install_base", "merge_install", "symlink_install", "cmake_args", "ament_cmake_args",
                 "cmake_target", "cmake_target_skip_unavailable", "cmake_clean_cache", "cmake_clean_first",
                 "cmake_force_configure", "jobs", "jobs_per_package", "package_cmake_args",
                 "package_ament_cmake_args", "force", "use_state")

    def __init__(
        self, build_base: Path, install_base: Path, *, merge_install: bool = False, symlink_install: bool = False,
        cmake_args: tuple[str, ...] = (), ament_cmake_args: tuple[str, ...] = (), cmake_target: str | None = None,
        cmake_target_skip_unavailable: bool = False, cmake_clean_cache: bool = False,
        cmake_clean_first: bool = False, cmake_force_configure: bool = False, jobs: int = 2,
        jobs_per_package: int = 2, package_cmake_args: dict[str, tuple[str, ...]] | None = None,
        package_ament_cmake_args: dict[str, tuple[str, ...]] | None = None, force: bool = False,
        use_state: bool = True,
    ) -> None:
        self.build_base = build_base
        self.install_base = install_base
        self.merge_install = merge_install
        self.symlink_install = symlink_install
        self.cmake_args = cmake_args
        self.ament_cmake_args = ament_cmake_args
        self.cmake_target = cmake_target
        self.cmake_target_skip_unavailable = cmake_target_skip_unavailable
        self.cmake_clean_cache = cmake_clean_cache
        self.cmake_clean_first = cmake_clean_first
        self.cmake_force_configure = cmake_force_configure
        self.jobs = jobs  # the global budget, shared through the make jobserver
        # for build tools that cannot join the jobserver (ninja): an equal share
        self.jobs_per_package = jobs_per_package
        # Per-package additions (roc.toml [package.NAME], colcon.meta), appended to the common arguments.
        self.package_cmake_args = package_cmake_args or {}
        self.package_ament_cmake_args = package_ament_cmake_args or {}
        self.force = force  # rebuild even when up to date
        self.use_state = use_state  # read and write fingerprints (--no-cache turns it off)

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


class PackageJob:
    """One package's build as a build type runs it: where its source, build directory and install
    prefix are, and the environment, jobserver and CMake arguments roc gives it."""

    def __init__(self, package: Package, source: Path, build_dir: Path, prefix: Path, *,
                 env: dict[str, str] | None = None, make_flags: str = "", pass_fds: tuple[int, ...] = (),
                 cmake_args: list[str] | None = None) -> None:
        self.package = package
        self.source = source  # absolute package directory
        self.build_dir = build_dir
        self.prefix = prefix  # the package's install prefix (the install base itself when merged)
        self.env = {} if env is None else env
        self.make_flags = make_flags  # MAKEFLAGS for make-based builds (jobserver client flags)
        self.pass_fds = pass_fds
        # roc's own CMake arguments, after the user's (the idl task's ROC_IDL_DIR)
        self.cmake_args = [] if cmake_args is None else cmake_args
