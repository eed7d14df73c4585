"""The repairs of ROS 2's PyPI wheels (roc/doctor/wheel_repairs.py), on copies of the files the wheels
install (their lines as the Jazzy wheels ship them)."""

from pathlib import Path

from roc.doctor import wheel_repairs
from roc.doctor.wheel_repairs import Interpreter

PYTHON = Interpreter(include="/usr/include/python3.11", numpy_include="/venv/site-packages/numpy/_core/include",
                     libpython="/usr/lib/x86_64-linux-gnu/libpython3.11.so")

GENERATOR_PY_EXPORT = """\
# Create imported target std_msgs::std_msgs__rosidl_generator_py
add_library(std_msgs::std_msgs__rosidl_generator_py SHARED IMPORTED)

set_target_properties(std_msgs::std_msgs__rosidl_generator_py PROPERTIES
  INTERFACE_INCLUDE_DIRECTORIES "/opt/python/cp311-cp311/include/python3.11;/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include"
)
"""
TRACETOOLS_LIBRARIES = """\
set(_exported_libraries "tracetools")
set(_exported_library_names "lttng-ust;dl")
"""
TRACETOOLS_TARGETS = """\
set_target_properties(tracetools::tracetools PROPERTIES
  INTERFACE_INCLUDE_DIRECTORIES "${_IMPORT_PREFIX}/include/tracetools;${_IMPORT_PREFIX}/include/tracetools"
  INTERFACE_LINK_LIBRARIES "lttng-ust;dl;-rdynamic;-ldl"
)
"""
FASTRTPS_TARGETS = """\
set_target_properties(fastrtps PROPERTIES
  INTERFACE_LINK_LIBRARIES "fastcdr;foonathan_memory;/usr/lib64/libtinyxml2.so;OpenSSL::SSL"
)
"""


def wheel_prefix(tmp_path: Path) -> Path:
    files = {
        "share/std_msgs/cmake/export_std_msgs__rosidl_generator_pyExport.cmake": GENERATOR_PY_EXPORT,
        "share/tracetools/cmake/ament_cmake_export_libraries-extras.cmake": TRACETOOLS_LIBRARIES,
        "share/tracetools/cmake/tracetools_exportExport.cmake": TRACETOOLS_TARGETS,
        "share/fastrtps/cmake/fastrtps-shared-targets.cmake": FASTRTPS_TARGETS,
    }
    for name, text in files.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    return tmp_path


def test_the_wheels_files_are_repaired_once_and_then_need_nothing(tmp_path):
    prefix = wheel_prefix(tmp_path)
    repairs = wheel_repairs.planned(prefix, PYTHON)
    assert sorted(r.path.relative_to(prefix).as_posix() for r in repairs) == [
        "share/fastrtps/cmake/fastrtps-shared-targets.cmake",
        "share/std_msgs/cmake/export_std_msgs__rosidl_generator_pyExport.cmake",
        "share/tracetools/cmake/ament_cmake_export_libraries-extras.cmake",
        "share/tracetools/cmake/tracetools_exportExport.cmake",
    ]
    wheel_repairs.apply(repairs)
    assert wheel_repairs.planned(prefix, PYTHON) == []
    tracetools = prefix / "share/tracetools/cmake"
    assert 'set(_exported_library_names "dl")' in (tracetools / "ament_cmake_export_libraries-extras.cmake").read_text()
    assert 'INTERFACE_LINK_LIBRARIES "dl;-rdynamic;-ldl"' in (tracetools / "tracetools_exportExport.cmake").read_text()
    fastrtps = (prefix / "share/fastrtps/cmake/fastrtps-shared-targets.cmake").read_text()
    assert '"fastcdr;foonathan_memory;OpenSSL::SSL"' in fastrtps


def test_a_generator_py_library_gets_this_pythons_includes_and_libpython_in_its_link_interface(tmp_path):
    prefix = wheel_prefix(tmp_path)
    wheel_repairs.apply(wheel_repairs.planned(prefix, PYTHON))
    text = (prefix / "share/std_msgs/cmake/export_std_msgs__rosidl_generator_pyExport.cmake").read_text()
    assert ('  INTERFACE_INCLUDE_DIRECTORIES "/usr/include/python3.11;/venv/site-packages/numpy/_core/include"\n'
            '  INTERFACE_LINK_LIBRARIES "-Wl,--no-as-needed;/usr/lib/x86_64-linux-gnu/libpython3.11.so;-Wl,--as-needed"'
            '\n)') in text
    assert "/opt/python" not in text


def test_a_libpython_of_another_python_is_replaced_by_this_ones(tmp_path):
    prefix = wheel_prefix(tmp_path)
    other = Interpreter(PYTHON.include, PYTHON.numpy_include, libpython="/opt/old/lib/libpython3.11.so")
    wheel_repairs.apply(wheel_repairs.planned(prefix, other))
    wheel_repairs.apply(wheel_repairs.planned(prefix, PYTHON))
    text = (prefix / "share/std_msgs/cmake/export_std_msgs__rosidl_generator_pyExport.cmake").read_text()
    assert text.count("INTERFACE_LINK_LIBRARIES") == 1 and "/opt/old" not in text
    assert wheel_repairs.planned(prefix, PYTHON) == []


def test_without_a_shared_libpython_only_the_include_paths_are_repaired(tmp_path):
    prefix = wheel_prefix(tmp_path)
    static = Interpreter(PYTHON.include, PYTHON.numpy_include, libpython=None)
    wheel_repairs.apply(wheel_repairs.planned(prefix, static))
    text = (prefix / "share/std_msgs/cmake/export_std_msgs__rosidl_generator_pyExport.cmake").read_text()
    assert "INTERFACE_LINK_LIBRARIES" not in text and "/usr/include/python3.11" in text


def test_tracetools_keeps_lttng_ust_where_the_library_is_installed_under_its_name(tmp_path):
    prefix = wheel_prefix(tmp_path)
    (prefix / "lib").mkdir()
    (prefix / "lib" / "liblttng-ust.so").write_text("")
    assert not any(r.path.parent.parent.name == "tracetools" for r in wheel_repairs.planned(prefix, PYTHON))


def test_an_installation_without_the_wheels_files_needs_no_repair(tmp_path):
    assert wheel_repairs.planned(tmp_path, PYTHON) == []


def test_doctor_reports_the_repairs_and_fix_applies_them(tmp_path, monkeypatch):
    import roc.environment
    from roc.commands.doctor import check
    from roc.doctor import environment

    prefix = wheel_prefix(tmp_path)
    monkeypatch.setattr(roc.environment, "own_prefix", lambda: prefix)
    monkeypatch.setattr(environment, "own_prefix", lambda: prefix)
    monkeypatch.setattr(wheel_repairs, "this_interpreter", lambda: PYTHON)
    finding = environment.wheels()
    assert (finding.level, finding.fix) == ("warning", "roc doctor --fix")
    assert finding.message.startswith(f"4 CMake file(s) of the ROS 2 wheels in {prefix} break builds: ")
    assert "links lttng-ust, which the wheel ships only under another name" in finding.message
    fixed = check._fix()
    assert len(fixed) == 4 and all(line.startswith(f"fixed {prefix}/share/") for line in fixed)
    assert environment.wheels().level == "ok"
    assert check._fix() == ["nothing to fix"]
