"""roc's tf buffer: the transforms heard on /tf and /tf_static, by child frame, and lookups between
any two frames of one tree through their common ancestor, with tf2's rules: a static transform holds
at every time, a dynamic one is interpolated between the stamps around the requested time (linear
translation, slerp rotation) and never extrapolated; time 0 asks for the latest time every dynamic
link of the chain has data for. No rclpy here: the frame verbs feed it from roc.ros.dataplane.
"""

from __future__ import annotations

import bisect
from collections import deque
from dataclasses import dataclass, field

from roc.errors import RocError
from roc.frames.transform import Transform, interpolate

CACHE_NS = 10 * 1_000_000_000  # tf2's default cache: 10 s of each dynamic transform
NS = 1e-9


class TransformUnavailable(RocError):
    """A lookup the buffer cannot answer (unknown or unconnected frames, a time outside the data)."""


@dataclass
class Link:
    """What connects ``child`` to its parent: one transform if static, else a history by stamp."""

    parent: str
    static: bool
    stamps: list[int] = field(default_factory=list)  # ns, sorted
    transforms: list[Transform] = field(default_factory=list)
    arrivals: deque = field(default_factory=lambda: deque(maxlen=1000))  # reception times, ns

    def add(self, stamp: int, transform: Transform, received: int) -> None:
        self.arrivals.append(received)
        if self.static:
            self.stamps, self.transforms = [stamp], [transform]
            return
        index = bisect.bisect_left(self.stamps, stamp)
        if index < len(self.stamps) and self.stamps[index] == stamp:
            self.transforms[index] = transform
        else:
            self.stamps.insert(index, stamp)
            self.transforms.insert(index, transform)
        while self.stamps and self.stamps[-1] - self.stamps[0] > CACHE_NS:
            del self.stamps[0], self.transforms[0]

    def at(self, stamp: int, child: str) -> Transform:
        if self.static or stamp == 0:
            return self.transforms[-1]
        if stamp > self.stamps[-1]:
            raise TransformUnavailable(f"lookup would need extrapolation into the future: asked for {stamp * NS:.3f}, "
                               f"the latest transform of {child} is at {self.stamps[-1] * NS:.3f}")
        if stamp < self.stamps[0]:
            raise TransformUnavailable(f"lookup would need extrapolation into the past: asked for {stamp * NS:.3f}, "
                               f"the oldest transform of {child} kept is at {self.stamps[0] * NS:.3f}")
        index = bisect.bisect_left(self.stamps, stamp)
        if self.stamps[index] == stamp:
            return self.transforms[index]
        before, after = self.stamps[index - 1], self.stamps[index]
        return interpolate(self.transforms[index - 1], self.transforms[index], (stamp - before) / (after - before))

    def rate(self) -> float | None:
        """Transforms per second over the arrivals kept (None before two)."""
        if len(self.arrivals) < 2 or self.arrivals[-1] == self.arrivals[0]:
            return None
        return (len(self.arrivals) - 1) / ((self.arrivals[-1] - self.arrivals[0]) * NS)


def frame_id(name: str) -> str:
    """tf2 ignores a leading slash."""
    return name.lstrip("/")


class Buffer:
    def __init__(self) -> None:
        self.links: dict[str, Link] = {}  # child -> link to its parent

    def add(self, parent: str, child: str, stamp: int, transform: Transform, static: bool, received: int = 0) -> None:
        parent, child = frame_id(parent), frame_id(child)
        link = self.links.get(child)
        if link is None or link.parent != parent or link.static != static:
            link = self.links[child] = Link(parent, static)  # a frame has one parent: the latest one heard
        link.add(stamp, transform, received)

    def frames(self) -> list[str]:
        return sorted({*self.links, *(link.parent for link in self.links.values())})

    def chain(self, frame: str) -> list[str]:
        """``frame`` and its ancestors up to its tree's root."""
        chain = [frame]
        while chain[-1] in self.links and self.links[chain[-1]].parent not in chain:
            chain.append(self.links[chain[-1]].parent)
        return chain

    def children(self, frame: str) -> list[str]:
        return sorted(child for child, link in self.links.items() if link.parent == frame)

    def roots(self) -> list[str]:
        return [frame for frame in self.frames() if frame not in self.links]

    def trees_text(self) -> str:
        """Every tree as its paths from the root, ``map->odom->base_link, map->laser; camera``."""
        def paths(frame: str) -> list[str]:
            below = self.children(frame)
            return [frame] if not below else [f"{frame}->{path}" for child in below for path in paths(child)]
        return "; ".join(", ".join(paths(root)) for root in self.roots())

    def lookup(self, target: str, source: str, stamp: int = 0) -> tuple[Transform, int]:
        """The pose of ``source`` in ``target`` (tf2's lookupTransform(target, source, time)) and the time
        it holds for; ``stamp`` 0: the latest time every dynamic link of the chain has data for."""
        target, source = frame_id(target), frame_id(source)
        known = self.frames()
        for name, role in ((target, "target"), (source, "source")):
            if name not in known:
                listed = ", ".join(known) or "none yet"
                raise TransformUnavailable(f"frame '{name}' ({role}) does not exist (frames: {listed})")
        up_from_source, up_from_target = self.chain(source), self.chain(target)
        common = next((frame for frame in up_from_source if frame in up_from_target), None)
        if common is None:
            raise TransformUnavailable(f"{target} and {source} are not connected (trees: {self.trees_text()})")
        links = [*up_from_source[:up_from_source.index(common)], *up_from_target[:up_from_target.index(common)]]
        dynamic = [self.links[child] for child in links if not self.links[child].static]
        if stamp == 0 and dynamic:
            stamp = min(link.stamps[-1] for link in dynamic)
        return (self._from(common, up_from_target, stamp).inverse() @ self._from(common, up_from_source, stamp)), stamp

    def _from(self, ancestor: str, chain: list[str], stamp: int) -> Transform:
        """The pose of ``chain[0]`` in ``ancestor`` (one of its ancestors in ``chain``)."""
        result = Transform()
        for child in reversed(chain[:chain.index(ancestor)]):
            result = result @ self.links[child].at(stamp, child)
        return result
