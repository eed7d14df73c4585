"""The PowerShell scripts (setup.ps1, local_setup.ps1, package.ps1, hook .ps1).

No PowerShell interpreter can be installed on this machine (none in its package registries), so these
tests cannot source the scripts. They parse every generated script with the PowerShell tree-sitter
grammar and check, on the parse tree, that each script does what its sh twin does: the same
variables, paths and package order.
"""

from __future__ import annotations

import os

import pytest
from helpers.build import BIN, copy_fixture, in_sourced_shell, roc
from helpers.powershell import PARSER, applied, check_package_scripts, parse, statements

from roc.environment.chain import Underlay
from roc.environment.dsv import Operation
from roc.shell.scripts import render


def test_the_parser_finds_errors():
    """The checks below mean something only if the grammar rejects broken PowerShell."""
    for broken in ("if ($a { . $b }\n", "$x = 'unterminated\n", "function f { \n"):
        assert PARSER.parse(broken.encode()).root_node.has_error, broken


def test_quoting_keeps_any_path():
    """Single quotes, PowerShell's typographic quotes, $, backticks and spaces in a path survive."""
    odd = "/w s/it's ‘x’ $HOME `n \"q\""
    text = render("setup.ps1.j2", underlays=[Underlay(odd)])
    assert ("=", "$_roc_setup_script", f"{odd}/local_setup.ps1") in statements(text)
    baked = render("setup.ps1.j2", underlays=[Underlay(odd, (Operation("prepend-non-duplicate", "PATH", ("bin",)),))])
    assert ("=", "$_roc_package_prefix", odd) in statements(baked)
    assert ("_roc_prepend_unique", "PATH", "PREFIX/bin") in applied(baked)


def test_every_dsv_operation_kind():
    operations = [Operation("prepend-non-duplicate", "PATH", ("bin", "")),
                  Operation("prepend-non-duplicate-if-exists", "PYTHONPATH", ("lib/site",)),
                  Operation("append-non-duplicate", "CMAKE_MODULE_PATH", ("/abs/cmake",)),
                  Operation("set", "ROBOT", ("share/robot.yaml",)),
                  Operation("set-if-unset", "RMW_IMPLEMENTATION", ("rmw_fastrtps_cpp",)),
                  Operation("source", "share/p/hook/user.ps1")]
    text = render("package.ps1.j2", package="p", prefix="/nowhere", operations=operations, up="../..")
    assert applied(text) == [
        ("_roc_prepend_unique", "PATH", "PREFIX/bin"), ("_roc_prepend_unique", "PATH", "PREFIX"),
        ("_roc_prepend_unique", "PYTHONPATH", "PREFIX/lib/site"), ("_roc_append_unique", "CMAKE_MODULE_PATH", "/abs/cmake"),
        ("_roc_set", "ROBOT", "PREFIX/share/robot.yaml"), ("_roc_set", "RMW_IMPLEMENTATION", "PREFIX/rmw_fastrtps_cpp")]
    found = statements(text)
    assert ("_roc_set", "ROBOT", "$_roc_package_path", "share/robot.yaml") in found  # the text when no such file
    assert ("Test-Path", "$_roc_package_path") in found  # the if-exists condition
    assert ("=", "$_roc_package_script", "$_roc_package_prefix", "/share/p/hook/user.ps1") in found
    assert (".", "$_roc_package_script") in found
    assert "if (-not [Environment]::GetEnvironmentVariable('RMW_IMPLEMENTATION')) { _roc_set" in text


@pytest.mark.slow
@pytest.mark.parametrize("merged", [False, True])
def test_scripts_parse_and_match_their_sh_twins(tmp_path, merged):
    ws = copy_fixture("build_small", tmp_path / "ws")
    result = roc("work", "build", *(["--merge-install"] if merged else []), cwd=ws)
    assert result.returncode == 0, result.stdout + result.stderr
    install = ws / "install"
    scripts = sorted(install.rglob("*.ps1"))
    packages = ["core", "app", "plain", "pyp"]  # the order of local_setup.sh
    assert len(scripts) == 2 + len(packages) + len(list(install.rglob("hook/*.dsv")))
    for script in scripts:
        parse(script.read_text())

    # local_setup.ps1: COLCON_PREFIX_PATH, then every package.ps1 in dependency order.
    local_setup = statements((install / "local_setup.ps1").read_text())
    assert local_setup[0] == ("=", "$_roc_base", "$PSScriptRoot")
    assert ("_roc_prepend_unique", "COLCON_PREFIX_PATH", "$_roc_base") in local_setup
    sourced = [s[2] for s in local_setup if s[:2] == ("Join-Path", "$_roc_base")]
    assert sourced == [f"{'' if merged else name + '/'}share/{name}/package.ps1" for name in packages]
    sh_order = [line for line in (install / "local_setup.sh").read_text().splitlines() if "package.sh" in line]
    assert [line.split("/share/")[1].split("/")[0] for line in sh_order[::2]] == packages

    check_package_scripts(install, packages, merged)

    # setup.ps1: its own local_setup.ps1, found next to it.
    assert statements((install / "setup.ps1").read_text())[-3:-1] == [
        ("Join-Path", "$PSScriptRoot", "local_setup.ps1"), (".", "$_roc_setup_script")]


@pytest.mark.slow
def test_setup_ps1_chains_the_underlays(tmp_path):
    underlay = copy_fixture("build_small", tmp_path / "under lay")
    overlay = tmp_path / "overlay"
    (overlay / "src").mkdir(parents=True)
    os.rename(underlay / "src" / "app", overlay / "src" / "app")
    assert roc("work", "build", cwd=underlay).returncode == 0
    built = in_sourced_shell(overlay, f"{BIN / 'roc'} work build", setup=str(underlay / "install" / "setup.bash"))
    assert built.returncode == 0, built.stdout + built.stderr
    chained = [s[2] for s in statements((overlay / "install" / "setup.ps1").read_text())
               if s[:2] == ("=", "$_roc_setup_script") and len(s) == 3]
    assert chained == [f"{underlay}/install/local_setup.ps1"]
