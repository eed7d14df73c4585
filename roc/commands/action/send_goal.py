"""roc action send_goal: send a goal to an action server and wait for the result (like ros2 action
send_goal); Ctrl+C cancels the goal and says so."""

from __future__ import annotations

import argparse
import contextlib
import signal

from roc.cli.options import add_graph_arguments, values_source
from roc.errors import RocError
from roc.render import print_json_line, print_text
from roc.ros.client import stream
from roc.ros.messages import fill_message, message_to_yaml, parse_values, value_to_data
from roc.ros.types import action_class


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("action_name", help="name of the action, e.g. /fibonacci")
    parser.add_argument("action_type", help="type of the action, e.g. example_interfaces/action/Fibonacci")
    source = parser.add_mutually_exclusive_group()
    source.add_argument("goal", nargs="?", help="goal field values in YAML, e.g. '{order: 5}' "
                                                "(default: the goal's default values)")
    source.add_argument("--stdin", action="store_true", help="read the goal's values (YAML) from standard input")
    parser.add_argument("-f", "--feedback", action="store_true", help="print the feedback messages")
    add_graph_arguments(parser)


def _indented(message) -> str:
    """The message's YAML as ros2 prints it after an indent: only its first line is indented."""
    return message_to_yaml(message).rstrip("\n")


def run(args: argparse.Namespace) -> int:
    """Exit 1 when the goal is rejected or does not succeed, 130 when canceled by Ctrl+C."""
    from roc.ros.cdr import decode, encode

    cls = action_class(args.action_type)
    request = fill_message(cls.Goal, parse_values(*values_source(args, "goal")))
    params = {"action": args.action_name, "type": args.action_type, "goal": encode(request),
              "feedback": args.feedback}
    text = args.format != "json"
    goal_id, canceling = None, False
    if text:  # as ros2, first, whether or not the server is already there
        print_text("Waiting for an action server to become available...\n")
    with _interruptible() as interrupted:
        for event in stream("goal", params, use_daemon=not args.no_daemon, heartbeats=True):
            kind = event["event"]
            if interrupted and goal_id is None:
                raise KeyboardInterrupt  # nothing to cancel yet
            if interrupted and goal_id is not None and not canceling:
                canceling = True
                _cancel(args, goal_id)  # then the server ends the goal, and the stream with its result
            if kind == "accepted":
                goal_id = event["goal_id"]
                if text:
                    print_text(f"Sending goal:\n     {_indented(request)}\n\nGoal accepted with ID: {goal_id}\n\n")
            elif kind == "rejected":
                if text:
                    print_text(f"Sending goal:\n     {_indented(request)}\n\n")
                raise RocError("Goal was rejected.")
            elif kind == "feedback":
                feedback = decode(cls.Feedback, event["data"])
                if text:
                    print_text(f"Feedback:\n    {_indented(feedback)}\n\n")
                else:
                    print_json_line({"action": args.action_name, "goal_id": goal_id,
                                     "feedback": value_to_data(feedback)})
            elif kind == "result":
                result = decode(cls.Result, event["data"])
                if canceling:
                    return 130
                if text:
                    print_text(f"Result:\n    {_indented(result)}\n\nGoal finished with status: {event['status']}\n")
                else:
                    print_json_line({"action": args.action_name, "goal_id": goal_id, "status": event["status"],
                                     "result": value_to_data(result)})
                return 0 if event["status"] == "SUCCEEDED" else 1
    return 1


@contextlib.contextmanager
def _interruptible():
    """A list that gets an entry at the first Ctrl+C (so the goal can be canceled); a second Ctrl+C
    interrupts as usual."""
    interrupted: list[bool] = []
    previous = signal.getsignal(signal.SIGINT)

    def first(*_: object) -> None:
        interrupted.append(True)
        signal.signal(signal.SIGINT, previous)

    signal.signal(signal.SIGINT, first)
    try:
        yield interrupted
    finally:
        signal.signal(signal.SIGINT, previous)


def cancel_call(action_name: str, goal_id: str) -> dict:
    """The ``call`` stream's params that ask the action's cancel service to cancel the goal (as plain
    data: the daemon fills the request and answers with plain data too)."""
    return {"service": f"{action_name}/_action/cancel_goal", "type": "action_msgs/srv/CancelGoal",
            "request_data": {"goal_info": {"goal_id": {"uuid": list(bytes.fromhex(goal_id))}}}}


def cancel_accepted(response: dict) -> bool:
    """Whether the cancel service's response (a ``call`` stream's ``response`` event) says the goal is
    being canceled."""
    return bool(response["value"]["goals_canceling"])


def _cancel(args: argparse.Namespace, goal_id: str) -> None:
    """Cancel the goal through the action's cancel service, and say how it went."""
    print_text("Canceling goal...\n")
    for event in stream("call", cancel_call(args.action_name, goal_id), use_daemon=not args.no_daemon):
        if event["event"] == "response":
            print_text("Goal canceled.\n" if cancel_accepted(event) else "Failed to cancel goal\n")
            return
