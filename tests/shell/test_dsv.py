"""Fast unit tests of colcon's .dsv files: reading, following sources, applying, and the hook writer."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

from roc.environment import path_list
from roc.environment.dsv import Operation, apply_operations, read_dsv, resolve_operations
from roc.shell.scripts import write_hook, write_package_scripts


def test_path_list_drops_empty_entries() -> None:
    assert path_list(None) == [] and path_list("") == []
    assert path_list(f"/a{os.pathsep}{os.pathsep}/b{os.pathsep}") == ["/a", "/b"]


def test_read_dsv(tmp_path: Path) -> None:
    dsv = tmp_path / "x.dsv"
    dsv.write_text("prepend-non-duplicate;PATH;bin\n\nset;NAME;a;b\nsource;share/p/hook/x.sh\n")
    assert read_dsv(dsv) == [("prepend-non-duplicate", "PATH", ("bin",)), ("set", "NAME", ("a", "b")),
                             ("source", "share/p/hook/x.sh", ())]


def test_resolve_follows_sources_with_a_dsv_twin_and_keeps_the_others(tmp_path: Path) -> None:
    hook = tmp_path / "share" / "p" / "hook"
    hook.mkdir(parents=True)
    (hook / "path.dsv").write_text("prepend-non-duplicate;PATH;bin\n")
    (hook / "path.sh").write_text("")
    (hook / "custom.sh").write_text("")
    package = tmp_path / "share" / "p" / "package.dsv"
    package.write_text("source;share/p/hook/path.sh\nsource;share/p/hook/custom.sh\nsource;share/p/hook/path.sh\n"
                       "set-if-unset;EMPTY;\n")
    assert resolve_operations(tmp_path, package) == [
        Operation("prepend-non-duplicate", "PATH", ("bin",)), Operation("source", "share/p/hook/custom.sh"),
        Operation("set-if-unset", "EMPTY", ("",))]


def test_apply_operations(tmp_path: Path) -> None:
    (tmp_path / "lib").mkdir()
    (tmp_path / "share").mkdir()
    env = {"PATH": f"/usr/bin{os.pathsep}{tmp_path}/bin", "KEEP": "mine"}
    apply_operations(env, tmp_path, [
        Operation("prepend-non-duplicate", "PATH", ("bin",)),
        Operation("prepend-non-duplicate-if-exists", "LD_LIBRARY_PATH", ("lib",)),
        Operation("prepend-non-duplicate-if-exists", "MISSING", ("nowhere",)),
        Operation("append-non-duplicate", "PATH", ("",)),
        Operation("set", "SHARE", ("share",)),
        Operation("set", "TEXT", ("plain words",)),
        Operation("set-if-unset", "KEEP", ("other",)),
        Operation("source", "share/p/hook/custom.sh"),
    ])
    assert env == {"PATH": os.pathsep.join([f"{tmp_path}/bin", "/usr/bin", str(tmp_path)]),
                   "LD_LIBRARY_PATH": f"{tmp_path}/lib", "SHARE": f"{tmp_path}/share", "TEXT": "plain words",
                   "KEEP": "mine"}


def test_hook_and_package_scripts_set_the_environment_in_sh(tmp_path: Path) -> None:
    prefix = tmp_path / "my prefix"
    hooks = write_hook(prefix, "p", "path", "prepend-non-duplicate;PATH;bin")
    assert hooks == ["share/p/hook/path.ps1", "share/p/hook/path.dsv", "share/p/hook/path.sh"]
    assert (prefix / "share/p/hook/path.dsv").read_text() == "prepend-non-duplicate;PATH;bin\n"
    write_package_scripts(prefix, "p", hooks)
    assert (prefix / "share/p/package.dsv").read_text() == "".join(f"source;{h}\n" for h in hooks)
    for script in ("share/p/hook/path.sh", "share/p/package.sh"):
        result = subprocess.run(["sh", "-c", f'. "{prefix}/{script}" && printf %s "$PATH"'],
                                env={"PATH": "/usr/bin:/bin"}, capture_output=True, text=True, check=True)
        assert result.stdout == f"{prefix}/bin:/usr/bin:/bin", script
