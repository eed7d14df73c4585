"""roc graph snapshot: the expectations the running system meets now, as a [check] table to edit and
then run with ``roc graph check --file``."""

from __future__ import annotations

import argparse

from roc.check.probes import measure_rates
from roc.cli.options import add_discovery_arguments
from roc.render import print_text

# Services every node offers (parameters, type descriptions) and topics every node publishes on (so that
# their counts change whenever any node joins): left out of a snapshot.
STANDARD_SERVICES = ("/describe_parameters", "/get_parameter_types", "/get_parameters", "/list_parameters",
                     "/set_parameters", "/set_parameters_atomically", "/get_type_description")
EVERY_NODES_TOPICS = ("/rosout", "/parameter_events")
RATE_MARGIN = 0.2  # min-rate and max-rate: the measured rate -/+ 20 %


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--rate-window", type=float, default=3.0, metavar="SECONDS",
                        help="how long to measure topic rates (default: 3; 0 for no rates)")
    add_discovery_arguments(parser)


def _rounded(value: float) -> float:
    return float(f"{value:.3g}")


def snapshot(session, rate_window: float) -> dict:
    from roc.ros.present import is_hidden

    graph = session.query("snapshot")
    nodes = sorted(n["full_name"] for n in graph["nodes"] if not is_hidden(n["full_name"]))
    topics = [t for t in graph["topics"] if not is_hidden(t["name"]) and t["name"] not in EVERY_NODES_TOPICS]
    rates = measure_rates(session, [t["name"] for t in topics if t["publishers"]], rate_window)
    check: dict = {"nodes": nodes, "topic": []}
    for topic in topics:
        info = session.query("topic_endpoints", {"topic": topic["name"]})
        entry: dict = {"name": topic["name"], "type": info["types"][0], "publishers": len(info["publishers"]),
                       "subscribers": len(info["subscribers"])}
        for policy in ("reliability", "durability"):
            offered = {p["qos"][policy].lower() for p in info["publishers"]}
            if len(offered) == 1:
                entry[policy] = offered.pop()
        if topic["name"] in rates:
            entry["min-rate"] = _rounded(rates[topic["name"]] * (1 - RATE_MARGIN))
            entry["max-rate"] = _rounded(rates[topic["name"]] * (1 + RATE_MARGIN))
        check["topic"].append(entry)
    check["service"] = [{"name": s["name"], "type": s["types"][0]} for s in graph["services"]
                        if not is_hidden(s["name"]) and not s["name"].endswith(STANDARD_SERVICES)]
    check["action"] = [{"name": a["name"], "type": a["types"][0]} for a in graph["actions"]]
    return {"check": {key: value for key, value in check.items() if value}}


def run(args: argparse.Namespace) -> int:
    import tomli_w

    from roc.ros.client import Session

    session = Session(use_daemon=not args.no_daemon, spin_time=args.spin_time)
    try:
        document = snapshot(session, args.rate_window)
    finally:
        session.close()
    print_text("# roc graph snapshot: what the running system met when it was taken; edit, then\n"
               "# roc graph check --file THIS_FILE\n" + tomli_w.dumps(document))
    return 0
