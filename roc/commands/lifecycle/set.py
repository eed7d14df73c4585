"""roc lifecycle set: trigger a transition of a managed node, by label or id (like ros2 lifecycle set);
exit 1 when the node refuses it."""

from __future__ import annotations

import argparse
import sys

from roc.commands.lifecycle.managed import add_node_arguments, managed_node, transitions
from roc.commands.node_services import call, session
from roc.errors import RocError
from roc.render import print_lines, render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_node_arguments(parser)
    parser.add_argument("transition", help="the transition's label or id, e.g. configure or 1")


def run(args: argparse.Namespace) -> int:
    from lifecycle_msgs.msg import Transition
    from lifecycle_msgs.srv import ChangeState

    with session(args) as opened:
        node = managed_node(opened, args)
        available = transitions(opened, node)
        chosen = next((t["transition"] for t in available if t["transition"]["label"] == args.transition), None) \
            or next((t["transition"] for t in available if str(t["transition"]["id"]) == args.transition), None)
        if chosen is None:
            raise RocError("Unknown transition requested, available ones are:" + "".join(
                f"\n- {t['transition']['label']} [{t['transition']['id']}]" for t in available))
        request = ChangeState.Request(transition=Transition(id=chosen["id"], label=chosen["label"]))
        success = call(opened, f"{node}/change_state", "lifecycle_msgs/srv/ChangeState", request).success
    if args.format == "json":
        render({"node": node, "transition": chosen, "success": success}, args.format)
    elif success:
        print_lines(["Transitioning successful"])
    else:
        print_lines(["Transitioning failed"], sys.stderr)
    return 0 if success else 1
