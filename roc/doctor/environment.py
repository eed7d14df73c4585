"""The environment checks of ``roc doctor``: the ROS distribution, the middleware, the domain, the
discovery range and the sourced overlays (AMENT_PREFIX_PATH), from the environment and the ament index
only (no rclpy)."""

from __future__ import annotations

import os
import platform
import re
from collections.abc import Mapping
from pathlib import Path

from roc import distribution as ros_distribution
from roc.ament_index import resources
from roc.doctor import build_tools, wheel_defects, wheel_repairs
from roc.doctor.findings import Finding
from roc.environment import ament_prefixes, own_prefix, path_list
from roc.ros import vendors

CATEGORY = "environment"
DEFAULT_RMW = "rmw_fastrtps_cpp"
DISCOVERY_RANGES = ("SUBNET", "LOCALHOST", "OFF", "SYSTEM_DEFAULT")
DOMAIN_MAX = 232  # Fast DDS derives its UDP ports from the domain; above this they do not fit
SAFE_DOMAINS = "0-101 and 215-232"  # domains whose ports never meet Linux's ephemeral ones
SHOWN = 5  # names listed in one finding


def package_version(package: str) -> str | None:
    """The version in an installed package's package.xml, None when it is not installed."""
    prefix = resources("packages").get(package)
    manifest = prefix / "share" / package / "package.xml" if prefix else None
    if manifest is None or not manifest.is_file():
        return None
    found = re.search(r"<version>\s*([^<\s]+)\s*</version>", manifest.read_text())
    return found.group(1) if found else None


def distribution(env: Mapping[str, str]) -> Finding:
    """The ROS 2 distribution (roc.distribution), and whether two are sourced: ROS_DISTRO against the
    rclpy found, or two rclpys (an overlay built on one distribution chains its rclpy in)."""
    found = ros_distribution.detected(env)
    if found is None:
        return Finding(CATEGORY, "distribution", "error", "no ROS 2 found: ROS_DISTRO is not set and no rclpy is in "
                       "the ament index", "source a ROS 2 setup script, e.g. /opt/ros/jazzy/setup.bash")
    mixed = ros_distribution.mix(env)
    if mixed:
        return Finding(CATEGORY, "distribution", "error", f"two distributions are sourced: {mixed}",
                       "open a new shell and source one distribution's setup script, and workspaces built on it")
    name, where = found
    text = f"{name} ({where.split(' in ')[0]})" if where != "ROS_DISTRO" else name
    if name in ros_distribution.END_OF_LIFE:
        return Finding(CATEGORY, "distribution", "warning", f"{text} is end-of-life: no more fixes or security updates",
                       "move to a supported distribution such as jazzy or kilted")
    if not env.get("ROS_DISTRO"):
        return Finding(CATEGORY, "distribution", "info", f"{text}; ROS_DISTRO is not set (ROS 2 from Python wheels?)")
    return Finding(CATEGORY, "distribution", "ok", text)


def installed_middlewares() -> list[str]:
    return sorted(name for name in resources("rmw_typesupport") if name != "rmw_implementation")


def middleware(env: Mapping[str, str]) -> Finding:
    chosen = env.get("RMW_IMPLEMENTATION") or DEFAULT_RMW
    installed = installed_middlewares()
    if installed and chosen not in installed:
        return Finding(CATEGORY, "middleware", "error", f"RMW_IMPLEMENTATION is {chosen}, which is not installed "
                       f"(installed: {', '.join(installed)})", f"unset RMW_IMPLEMENTATION or install {chosen}")
    default = "" if env.get("RMW_IMPLEMENTATION") else " (the default)"
    return Finding(CATEGORY, "middleware", "ok", f"{chosen}{default}; discovery: {vendors.discovery_of(chosen)}",
                   details={"installed": installed})


def domain(env: Mapping[str, str]) -> Finding:
    text = env.get("ROS_DOMAIN_ID", "")
    if not text:
        return Finding(CATEGORY, "domain", "ok", "0 (ROS_DOMAIN_ID is not set)")
    if not text.isdigit():
        return Finding(CATEGORY, "domain", "error", f"ROS_DOMAIN_ID '{text}' is not a number",
                       f"set ROS_DOMAIN_ID to a number in {SAFE_DOMAINS}")
    number = int(text)
    if number > DOMAIN_MAX:
        return Finding(CATEGORY, "domain", "error", f"ROS_DOMAIN_ID {number} is above {DOMAIN_MAX}: its ports do not "
                       "exist", f"choose a domain in {SAFE_DOMAINS}")
    if 101 < number < 215:
        return Finding(CATEGORY, "domain", "warning", f"{number}: its ports may collide with Linux's ephemeral ports",
                       f"choose a domain in {SAFE_DOMAINS}")
    return Finding(CATEGORY, "domain", "ok", str(number))


def discovery(env: Mapping[str, str]) -> list[Finding]:
    range_ = env.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "")
    peers = env.get("ROS_STATIC_PEERS", "")
    findings = []
    if range_ and range_ not in DISCOVERY_RANGES:
        findings.append(Finding(CATEGORY, "discovery", "error", f"ROS_AUTOMATIC_DISCOVERY_RANGE '{range_}' is not "
                                f"one of {', '.join(DISCOVERY_RANGES)}", "set one of those, or unset it (SUBNET)"))
    if env.get("ROS_LOCALHOST_ONLY"):
        findings.append(Finding(CATEGORY, "discovery", "warning", "ROS_LOCALHOST_ONLY is deprecated since Jazzy",
                                "unset it; use ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST instead of "
                                "ROS_LOCALHOST_ONLY=1"))
    if range_ == "OFF" and not peers:
        findings.append(Finding(CATEGORY, "discovery", "warning", "ROS_AUTOMATIC_DISCOVERY_RANGE is OFF and "
                                "ROS_STATIC_PEERS is empty: nodes find no other process",
                                "use LOCALHOST or SUBNET, or list the peers in ROS_STATIC_PEERS"))
    if not findings:
        text = f"{range_ or 'SUBNET'}{'' if range_ else ' (the default)'}"
        findings.append(Finding(CATEGORY, "discovery", "ok", text + (f", static peers: {peers}" if peers else "")))
    return findings


def _packages(prefix: Path) -> set[str]:
    directory = prefix / "share" / "ament_index" / "resource_index" / "packages"
    if not directory.is_dir():
        return set()
    return {entry.name for entry in directory.iterdir() if not entry.name.startswith(".")}


def _names(names: list[str]) -> str:
    more = len(names) - SHOWN
    return ", ".join(names[:SHOWN]) + (f" and {more} more" if more > 0 else "")


def overlays(env: Mapping[str, str]) -> list[Finding]:
    """Prefixes on AMENT_PREFIX_PATH that do not exist, and packages of one prefix that shadow the
    same packages of a later one."""
    if not env.get("AMENT_PREFIX_PATH"):
        return [Finding(CATEGORY, "overlays", "info", "AMENT_PREFIX_PATH is not set: no workspace is sourced")]
    findings = []
    seen: dict[str, Path] = {}
    shadowed: dict[tuple[Path, Path], list[str]] = {}
    listed = [Path(p) for p in path_list(env["AMENT_PREFIX_PATH"])]
    for prefix in listed:
        if not prefix.is_dir():
            findings.append(Finding(CATEGORY, "overlays", "warning", f"{prefix} (on AMENT_PREFIX_PATH) does not exist",
                                    "source the setup script of an existing workspace in a new shell"))
            continue
        for package in sorted(_packages(prefix)):
            if package in seen:
                shadowed.setdefault((seen[package], prefix), []).append(package)
            else:
                seen[package] = prefix
    for (over, under), names in shadowed.items():
        findings.append(Finding(CATEGORY, "overlays", "warning",
                                f"{len(names)} package(s) of {over} shadow those of {under}: {_names(names)}",
                                "expected when the overlay overrides them on purpose; otherwise remove them from it",
                                details={"overlay": str(over), "underlay": str(under), "packages": names}))
    if not findings:
        findings.append(Finding(CATEGORY, "overlays", "ok", f"{len(listed)} prefix(es), no package shadowed"))
    return findings


def wheels(repairs: list[wheel_repairs.Repair] | None = None) -> Finding:
    """Whether ROS 2 installed from PyPI wheels into roc's own environment needs the repairs without which
    ament_cmake builds and C++ programs fail (roc.doctor.wheel_repairs); ``roc doctor --fix`` applies them."""
    prefix = own_prefix()
    if prefix is None:
        return Finding(CATEGORY, "ros wheels", "ok", "no ROS 2 wheels in roc's environment")
    if repairs is None:
        repairs = wheel_repairs.planned(prefix, wheel_repairs.this_interpreter())
    if not repairs:
        return Finding(CATEGORY, "ros wheels", "ok", f"the ROS 2 wheels in {prefix} need no repair")
    reasons = sorted({repair.why for repair in repairs})
    return Finding(CATEGORY, "ros wheels", "warning",
                   f"{len(repairs)} CMake file(s) of the ROS 2 wheels in {prefix} break builds: " + "; ".join(reasons),
                   "roc doctor --fix", details={"files": [str(repair.path) for repair in repairs]})


def checks(env: Mapping[str, str] = os.environ) -> list[Finding]:
    return [distribution(env), middleware(env), domain(env), *discovery(env), *overlays(env), wheels(),
            build_tools.tools(env), build_tools.ament_python(env), wheel_defects.missing_packages(env),
            wheel_defects.linked_rmw(env)]


def reports(env: Mapping[str, str] = os.environ) -> dict[str, list[tuple[str, str]]]:
    """ros2 doctor's platform, ROS 2 and middleware reports, and the ROS environment variables."""
    ros = [("distribution name", env.get("ROS_DISTRO", "") or "(ROS_DISTRO is not set)"),
           ("rclpy version", package_version("rclpy") or "(not found)")]
    variables = [(name, value) for name, value in sorted(env.items())
                 if name.startswith(("ROS_", "RMW_", "FASTRTPS_", "FASTDDS_", "CYCLONEDDS_"))]
    return {
        "PLATFORM INFORMATION": [("system", platform.system()), ("platform info", platform.platform()),
                                 ("release", platform.release()), ("processor", platform.processor())],
        "ROS 2 INFORMATION": ros,
        "ROS ENVIRONMENT": variables + [("AMENT_PREFIX_PATH", str(p)) for p in ament_prefixes()],
        "RMW MIDDLEWARE": [("middleware name", env.get("RMW_IMPLEMENTATION") or DEFAULT_RMW)],
    }
