"""Which process runs each node, and its CPU and memory (psutil), for the nodes on this host.

An endpoint's gid starts with its participant's GUID prefix, so each node's /rosout or /parameter_events
publisher names its participant, and the participant its process:
- Fast DDS 2.14 writes the process into every participant's GUID prefix (roc.ros.vendors.fastdds): the
  16 low bits of the process id. A local process whose pid has those bits and which holds a metatraffic
  unicast port of the domain (UDP 7400 + 250 * domain + 10 + 2 * k, the RTPS default Fast DDS uses; k is
  the first index free on the host, not the counter) is the one.
- Cyclone DDS writes no process into its GUIDs, but a participant announces its host name and process id
  (``__Hostname``, ``__Pid``): roc asks this host's participants to announce themselves to a socket of its
  own (roc.ros.discovery.LocalParticipantProbe), a few times at most, and reads them there.
A node whose participant no local process holds or tells runs on another host (or in another network
namespace).
"""

from __future__ import annotations

import os
import socket
from collections import Counter
from dataclasses import dataclass
from typing import Any

import psutil

from roc.ros.discovery import LocalParticipantProbe, is_metatraffic_port
from roc.ros.protocol import full_name
from roc.ros.vendors.fastdds import process_bits

ASKS = 3  # how often the participants of this host are asked to announce themselves for one participant


@dataclass(frozen=True)
class Participant:
    prefix: str  # the GUID prefix, 12 bytes as dotted hex
    pid_bits: int | None  # Fast DDS: the 16 low bits of its process id; None for another vendor's


def participant(gid: str) -> Participant | None:
    """The participant of an endpoint gid (``01.0f.7f.01.f3.5f...``), None when it is no GUID."""
    parts = gid.split(".")
    if len(parts) < 12:
        return None
    return Participant(".".join(parts[:12]), process_bits(bytes(int(part, 16) for part in parts[:12])))


def node_participants(snapshot: dict[str, Any]) -> dict[str, Participant]:
    """Each node's participant, from the endpoints of a ``snapshot {"endpoints": true}``."""
    found: dict[str, Participant] = {}
    for topic in snapshot["topics"]:
        endpoints = topic.get("endpoints") or {}
        for endpoint in [*endpoints.get("publishers", []), *endpoints.get("subscribers", [])]:
            name = full_name(endpoint["node_namespace"], endpoint["node_name"])
            if name not in found and (found_participant := participant(endpoint["gid"])) is not None:
                found[name] = found_participant
    return found


@dataclass
class Usage:
    """What the nodes list shows of a node's process: ``pid`` None when it runs elsewhere."""

    pid: int | None
    cpu: float | None = None  # % of one core since the last update
    rss: int | None = None  # bytes
    nodes: int = 1  # nodes in the same process

    @property
    def where(self) -> str:
        return "this host" if self.pid is not None else "another host"


class Processes:
    """Finds the processes of participants once, then measures them at each ``update``."""

    def __init__(self, domain: int | None = None) -> None:
        self.domain = domain if domain is not None else int(os.environ.get("ROS_DOMAIN_ID") or 0)
        self._found: dict[str, psutil.Process | None] = {}  # participant prefix -> its process
        self._probe: LocalParticipantProbe | None = None  # made for the first participant not Fast DDS's
        self._asked: Counter[str] = Counter()  # participant prefix -> how often the probe asked for it
        self.usage: dict[str, Usage] = {}  # node -> usage

    def locate(self, found: Participant) -> psutil.Process | None:
        if found.prefix in self._found:
            cached = self._found[found.prefix]
            if cached is None or cached.is_running():
                return cached
        if found.pid_bits is None:
            return self._announced_process(found)
        process = None
        for pid in psutil.pids():
            if pid & 0xFFFF != found.pid_bits:
                continue
            try:
                candidate = psutil.Process(pid)
                if any(c.laddr and is_metatraffic_port(c.laddr.port, self.domain)
                       for c in candidate.net_connections("udp")):
                    process = candidate
                    break
            except (psutil.NoSuchProcess, psutil.AccessDenied, psutil.ZombieProcess):
                continue
        self._found[found.prefix] = process
        return process

    def _announced_process(self, found: Participant) -> psutil.Process | None:
        """The process a participant announced as its own on this host (Cyclone DDS: ``__Pid`` and
        ``__Hostname``); None until its answer comes (by a later update), and for good after ASKS asks."""
        if self._probe is None:
            self._probe = LocalParticipantProbe(self.domain)
        announced = self._probe.announced().get(bytes.fromhex(found.prefix.replace(".", "")), {})
        pid = announced.get("__Pid", "")
        if not announced or announced.get("__Hostname") != socket.gethostname() or not pid.isdigit():
            if announced or self._asked[found.prefix] >= ASKS:
                self._found[found.prefix] = None  # another host's, or it tells no process
            elif self._probe.ask_again():
                self._asked[found.prefix] += 1
            return None
        try:
            process: psutil.Process | None = psutil.Process(int(pid))
        except psutil.Error:
            process = None
        self._found[found.prefix] = process
        return process

    def update(self, snapshot: dict[str, Any]) -> dict[str, Usage]:
        """Each node's process and its CPU (since the last update) and resident memory."""
        participants = node_participants(snapshot)
        per_process: dict[int, int] = {}
        located: dict[str, psutil.Process | None] = {}
        for node, found in participants.items():
            located[node] = process = self.locate(found)
            if process is not None:
                per_process[process.pid] = per_process.get(process.pid, 0) + 1
        measured: dict[int, tuple[float | None, int | None]] = {}
        usage = {}
        for node, process in located.items():
            if process is None:
                usage[node] = Usage(None)
                continue
            if process.pid not in measured:
                try:
                    with process.oneshot():
                        measured[process.pid] = (process.cpu_percent(), process.memory_info().rss)
                except (psutil.NoSuchProcess, psutil.AccessDenied, psutil.ZombieProcess):
                    measured[process.pid] = (None, None)
            cpu, rss = measured[process.pid]
            usage[node] = Usage(process.pid, cpu, rss, per_process[process.pid])
        self.usage = usage
        return usage


def cpu_text(usage: Usage | None) -> str:
    if usage is None:
        return ""
    if usage.pid is None:
        return "remote"
    return "-" if usage.cpu is None else f"{usage.cpu:.0f}%"


def memory_text(usage: Usage | None) -> str:
    if usage is None or usage.rss is None:
        return ""
    megabytes = usage.rss / 1e6
    return f"{megabytes:.0f}M" if megabytes < 10000 else f"{megabytes / 1000:.0f}G"
