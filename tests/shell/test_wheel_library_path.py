"""A workspace built on ROS 2 from PyPI wheels: its setup scripts give C++ programs the library folders
the wheels need at run time and no package hook names (the wheels' bundled libraries in
site-packages/ros_*.libs, the interpreter's shared libpython outside the linker's search path)."""

from __future__ import annotations

import subprocess
from pathlib import Path

from roc.environment.chain import chained_underlays, prefix_operations
from roc.environment.dsv import Operation
from roc.shell.scripts import write_install_scripts

LIBRARIES = "LD_LIBRARY_PATH"


def wheel_venv(root: Path, python_home: Path) -> Path:
    """A venv of ROS 2 wheels: rcl registered with its hook, two ros_*.libs folders, a pyvenv.cfg."""
    venv = root / "venv"
    (venv / "share" / "ament_index" / "resource_index" / "packages").mkdir(parents=True)
    (venv / "share" / "ament_index" / "resource_index" / "packages" / "rcl").write_text("")
    (venv / "share" / "rcl").mkdir(parents=True)
    (venv / "share" / "rcl" / "package.dsv").write_text(f"prepend-non-duplicate;{LIBRARIES};lib\n")
    site = venv / "lib" / "python3.11" / "site-packages"
    for name in ("ros_rcl.libs", "ros_fastrtps.libs"):
        (site / name).mkdir(parents=True)
    (venv / "pyvenv.cfg").write_text(f"home = {python_home / 'bin'}\ninclude-system-site-packages = false\n")
    return venv


def pyenv_python(root: Path) -> Path:
    """A Python installed outside the linker's folders, with its shared libpython (as pyenv builds it)."""
    home = root / "pyenv" / "3.11.7"
    (home / "bin").mkdir(parents=True)
    (home / "lib").mkdir()
    (home / "lib" / "libpython3.11.so.1.0").write_text("")
    return home


def test_the_wheels_bundled_library_folders_and_libpython_s_are_among_a_wheel_prefix_s_operations(
        tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    home = pyenv_python(tmp_path)
    venv = wheel_venv(tmp_path, home)
    site = "lib/python3.11/site-packages"
    assert prefix_operations(venv) == (
        Operation("prepend-non-duplicate", LIBRARIES, ("lib",)),
        Operation("prepend-non-duplicate", LIBRARIES, (f"{site}/ros_fastrtps.libs",)),
        Operation("prepend-non-duplicate", LIBRARIES, (f"{site}/ros_rcl.libs",)),
        Operation("prepend-non-duplicate", LIBRARIES, (str(home / "lib"),)),
    )


def test_a_python_whose_libpython_the_linker_finds_adds_no_folder(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    venv = wheel_venv(tmp_path, Path("/usr"))  # Debian's python3: libpython in /usr/lib/<multiarch>
    values = [op.values[0] for op in prefix_operations(venv)]
    assert values == ["lib", "lib/python3.11/site-packages/ros_fastrtps.libs",
                      "lib/python3.11/site-packages/ros_rcl.libs"]


def test_sourcing_a_workspace_built_on_the_wheels_gives_its_programs_their_library_folders(
        tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    home = pyenv_python(tmp_path)
    venv = wheel_venv(tmp_path, home)
    base = tmp_path / "ws" / "install"
    base.mkdir(parents=True)
    write_install_scripts(base, [], merged=False,
                          underlays=chained_underlays({"AMENT_PREFIX_PATH": str(venv)}, base))
    result = subprocess.run(["bash", "-c", f'source "$1" && printf %s "${LIBRARIES}"', "_", str(base / "setup.bash")],
                            capture_output=True, text=True, env={"PATH": "/usr/bin:/bin"}, check=True)
    site = venv / "lib" / "python3.11" / "site-packages"
    assert result.stdout.split(":") == [str(home / "lib"), str(site / "ros_rcl.libs"), str(site / "ros_fastrtps.libs"),
                                        str(venv / "lib")]


def test_a_wheel_venv_entry_already_listed_keeps_its_place_as_colcon_leaves_it(tmp_path: Path, monkeypatch) -> None:
    """A workspace W sourced first, then the setup script of another install U built on the same wheels:
    W's libraries stay before the venv's (colcon's scripts never touch the venv's entries)."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    venv = wheel_venv(tmp_path, pyenv_python(tmp_path))
    base = tmp_path / "u" / "install"
    base.mkdir(parents=True)
    write_install_scripts(base, [], merged=False,
                          underlays=chained_underlays({"AMENT_PREFIX_PATH": str(venv)}, base))
    sourced_first = f"/w/install/w_pkg/lib:{venv}/lib"
    result = subprocess.run(["bash", "-c", f'source "$1" && printf %s "${LIBRARIES}"', "_", str(base / "setup.bash")],
                            capture_output=True, text=True, check=True,
                            env={"PATH": "/usr/bin:/bin", LIBRARIES: sourced_first})
    entries = result.stdout.split(":")
    assert entries.index("/w/install/w_pkg/lib") < entries.index(f"{venv}/lib"), entries
    assert entries[-2:] == ["/w/install/w_pkg/lib", f"{venv}/lib"]
