"""layered_order (Kahn's algorithm by hand) against a reference built on the stdlib's graphlib, which
it replaced for speed: the same order on random graphs, in both modes, and graphlib's cycle error."""

from __future__ import annotations

import random
from graphlib import CycleError, TopologicalSorter

import pytest

from roc.workspace.dependencies import layered_order


def _reference(dependencies: dict[str, set[str]], one_at_a_time: bool) -> list[str]:
    sorter = TopologicalSorter({name: deps & dependencies.keys() for name, deps in dependencies.items()})
    sorter.prepare()
    ordered: list[str] = []
    ready: list[str] = []
    while sorter.is_active():
        ready.extend(sorter.get_ready())
        ready.sort()
        placed = ready[:1] if one_at_a_time else ready[:]
        del ready[:len(placed)]
        ordered.extend(placed)
        sorter.done(*placed)
    return ordered


def test_same_order_as_graphlib_layering_on_random_graphs() -> None:
    rng = random.Random(7)
    for _ in range(300):
        names = [f"p{rng.randint(0, 999):03d}_{i}" for i in range(rng.randint(0, 40))]
        graph = {name: {rng.choice(names[:i]) for _ in range(rng.randint(0, 3))} if i else set()
                 for i, name in enumerate(names)}
        for deps in graph.values():
            if rng.random() < 0.2:
                deps.add("outside_the_workspace")
        for one_at_a_time in (False, True):
            assert layered_order(graph, one_at_a_time) == _reference(graph, one_at_a_time)


def test_layers_are_alphabetical_and_a_cycle_is_graphlibs_error() -> None:
    assert layered_order({"c": set(), "b": {"c"}, "a": {"c"}, "z": set()}) == ["c", "z", "a", "b"]
    assert layered_order({"c": set(), "b": {"c"}, "a": {"c"}, "z": set()}, one_at_a_time=True) == ["c", "a", "b", "z"]
    with pytest.raises(CycleError) as raised:
        layered_order({"a": {"b"}, "b": {"a"}, "c": set()})
    assert raised.value.args[1] in (["a", "b", "a"], ["b", "a", "b"])
