"""roc.ros.dataplane.PublisherNames: the node behind a tf message's publisher gid; where the middleware gives
an instance handle instead of the writer's GUID (Cyclone DDS), the topic's one publishing node, and no name
when several publish it."""

from __future__ import annotations

from types import SimpleNamespace

from roc.ros.dataplane import PublisherNames

FAST_GID = "01.0f.7f.01.f3.5f.00.00.01.00.00.00.00.00.12.03"
CYCLONE_WRITER = "01.10.45.12.ab.cd.00.00.01.00.00.00.00.00.12.03"
HANDLE = "5a.c3.11.09.7e.21.04.9f.00.00.00.00.00.00.00.00"  # what Cyclone's message info holds


def graph_of(*publishers: tuple[str, str]) -> SimpleNamespace:
    infos = [SimpleNamespace(node_name=name, node_namespace="/", endpoint_gid=bytes.fromhex(gid.replace(".", "")))
             for name, gid in publishers]
    return SimpleNamespace(node=SimpleNamespace(get_publishers_info_by_topic=lambda topic: infos))


def test_a_writer_guid_names_its_node() -> None:
    names = PublisherNames(graph_of(("broadcaster", FAST_GID), ("other", "01.0f.7f.01.f3.5f.00.00.02.00.00.00.00.00.12.03")))
    assert names.name("/tf", FAST_GID) == "/broadcaster"


def test_an_instance_handle_is_named_only_while_one_node_publishes_the_topic() -> None:
    assert PublisherNames(graph_of(("static_pub", CYCLONE_WRITER))).name("/tf_static", HANDLE) == "/static_pub"
    assert PublisherNames(graph_of(("a", CYCLONE_WRITER), ("b", FAST_GID))).name("/tf_static", HANDLE) is None
