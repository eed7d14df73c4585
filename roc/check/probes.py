"""One probe per expectation: it asks the graph (through a roc.ros.client.Session, shared by all
probes) and says pass or fail with what it measured and what was expected. A probe that cannot ask
(the graph layer fails, a time limit passes) is an error. Probes run as ``probe`` tasks of roc's
engine (``probe_task``): for roc graph check, roc launch --check, and the conditions of roc.toml's launch
systems, which probe again until the condition holds (``probe_until``)."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TextIO

from roc.check.expectations import Expectation
from roc.engine.events import Event, ProbeResult
from roc.engine.process import TaskCancelled, TaskContext, TaskError
from roc.engine.ready import Task
from roc.errors import RocError
from roc.render import plural, to_yaml_line
from roc.ros.present import is_hidden, qos_problems
from roc.ros.rates import Window, samples


@dataclass
class Verdict:
    status: str  # pass, fail, error
    message: str  # what was found (and, on failure, what was expected)
    measured: Any = None


class Failed(Exception):
    """The graph does not meet the expectation."""

    def __init__(self, message: str, measured: Any = None):
        super().__init__(message)
        self.measured = measured


def probe(expectation: Expectation, session, timeout: float, rate_window: float) -> Verdict:
    """Run the expectation's probe."""
    try:
        message, measured = PROBES[expectation.kind](expectation, session, timeout, rate_window)
    except Failed as failure:
        return Verdict("fail", str(failure), failure.measured)
    except RocError as error:
        return Verdict("error", str(error))
    return Verdict("pass", message, measured)


KIND = "probe"  # the engine's kind of a probe task
RETRY_SECONDS = 0.25


def probe_until(expectation: Expectation, session, timeout: float, rate_window: float, wait: float,
                stopped: Callable[[], bool] = lambda: False) -> Verdict:
    """Probe again until the expectation holds or ``wait`` seconds have passed (a system coming up):
    the last verdict. Raises TaskCancelled once ``stopped`` says so."""
    deadline = time.monotonic() + wait
    while True:
        verdict = probe(expectation, session, timeout, rate_window)
        if verdict.status == "pass" or time.monotonic() >= deadline:
            return verdict
        if stopped():
            raise TaskCancelled
        time.sleep(RETRY_SECONDS)


def probe_task(expectation: Expectation, session, timeout: float, rate_window: float, wait: float = 0.0,
               stopped: Callable[[], bool] = lambda: False) -> Task:
    """One engine task of kind ``probe``: it emits the ProbeResult, and fails unless the probe passed
    (within ``wait`` seconds, probing again and again until it passes or ``stopped`` says so)."""

    def action(context: TaskContext) -> None:
        verdict = probe_until(expectation, session, timeout, rate_window, wait,
                              lambda: context.cancelled or stopped())
        context.emit(ProbeResult(expectation.label, KIND, status=verdict.status, message=verdict.message,
                                 expected=expectation.values, measured=verdict.measured))
        if verdict.status != "pass":
            raise TaskError(f"{verdict.status}: {verdict.message} ({expectation.where})")

    return Task(name=expectation.label, dependencies=set(), action=action, kind=KIND)


def probe_console(stream: TextIO) -> list[Callable[[Event], None]]:
    """The handlers that print probe tasks as ``roc graph check`` does: each probe's line with what it
    found, and the summary."""
    from roc.handlers.console import ConsoleHandler

    found: dict[str, str] = {}

    def remember(event: Event) -> None:
        if isinstance(event, ProbeResult):
            found[event.key] = event.message

    return [remember, ConsoleHandler(stream, kind=KIND, noun="probe", cached_label="",
                                     finished_note=lambda key: f"  {found.get(key, '')}")]


def _snapshot(session) -> dict[str, Any]:
    return session.query("snapshot")


def _node(expectation: Expectation, session, _timeout: float, _window: float) -> tuple[str, Any]:
    names = [node["full_name"] for node in _snapshot(session)["nodes"]]
    if expectation.name not in names:
        shown = sorted(name for name in names if not is_hidden(name))
        raise Failed(f"no node {expectation.name} (nodes: {', '.join(shown) or 'none'})")
    return "running", expectation.name


def _topic(expectation: Expectation, session, timeout: float, window: float) -> tuple[str, Any]:
    """Every expectation of the topic is checked, and every one it misses is reported (a QoS problem
    does not hide a rate below ``min-rate``)."""
    expected = expectation.values
    try:
        info = session.query("topic_endpoints", {"topic": expectation.name})
    except RocError:
        raise Failed(f"no topic {expectation.name}") from None
    found: list[str] = [f"type {', '.join(info['types'])}"]
    failures: list[str] = []
    measured: dict[str, Any] = {"types": info["types"], "publishers": len(info["publishers"]),
                                "subscribers": len(info["subscribers"])}
    if "type" in expected and expected["type"] not in info["types"]:
        failures.append(f"type {', '.join(info['types'])}, expected {expected['type']}")
    for side in ("publishers", "subscribers"):
        if side in expected and measured[side] != expected[side]:
            failures.append(f"{measured[side]} {side}, expected {expected[side]}")
    for policy in ("reliability", "durability"):
        if policy in expected:
            offered = sorted({p["qos"][policy].lower() for p in info["publishers"]})
            if offered != [expected[policy]]:
                failures.append(f"publishers offer {policy} {', '.join(offered) or 'nothing'}, expected "
                                f"{expected[policy]}")
    if expected.get("compatible", True):
        failures += _qos_incompatibilities(info)
    if "min-rate" in expected or "max-rate" in expected:
        rate = measure_rates(session, [expectation.name], min(window, timeout)).get(expectation.name)
        measured["rate"] = rate
        bounds = " to ".join(f"{expected[k]:g}" for k in ("min-rate", "max-rate") if k in expected)
        if rate is None:
            failures.append(f"no messages in {window:g} s, expected {bounds} Hz")
        elif rate < expected.get("min-rate", 0.0) or rate > expected.get("max-rate", float("inf")):
            failures.append(f"{rate:.2f} Hz, expected {bounds} Hz")
        else:
            found.append(f"{rate:.2f} Hz")
    if failures:
        raise Failed("; ".join(failures), measured)
    found.append(f"{plural(measured['publishers'], 'publisher')}, {plural(measured['subscribers'], 'subscriber')}")
    return ", ".join(found), measured


def _qos_incompatibilities(info: dict[str, Any]) -> list[str]:
    """The first QoS problem of each publisher-subscriber pair that cannot match."""
    found = []
    for publisher in info["publishers"]:
        for subscriber in info["subscribers"]:
            problems = qos_problems(publisher, subscriber)
            if problems:
                found.append(f"QoS incompatible ({problems[0]['policy']}): {publisher['node_name']} -> "
                             f"{subscriber['node_name']}: {problems[0]['message']}")
    return found


def measure_rates(session, topics: list[str], seconds: float) -> dict[str, float]:
    """The publishers' rate of each topic over ``seconds`` (topics with fewer than two messages left out)."""
    windows = {topic: Window(1_000_000) for topic in topics}
    if seconds <= 0 or not topics:
        return {}
    deadline = time.monotonic() + seconds
    for event in session.stream("stats", {"topics": topics, "period": min(0.5, seconds)}, heartbeats=True):
        if event["event"] == "batch":
            for topic, columns in event["topics"].items():
                windows[topic].add(samples(columns))
        if time.monotonic() >= deadline:
            break
    rates = {topic: window.rate() for topic, window in windows.items()}
    return {topic: rate["rate"] for topic, rate in rates.items() if rate}


def _service(expectation: Expectation, session, timeout: float, _window: float) -> tuple[str, Any]:
    expected = expectation.values
    services = {s["name"]: s["types"] for s in _snapshot(session)["services"]}
    if expectation.name not in services:
        raise Failed(f"no service {expectation.name}")
    types = services[expectation.name]
    if "type" in expected and expected["type"] not in types:
        raise Failed(f"type {', '.join(types)}, expected {expected['type']}", types)
    if "request" not in expected and "response" not in expected:
        return f"served ({', '.join(types)})", types
    from roc.ros.cdr import decode, encode
    from roc.ros.messages import fill_message, parse_values, value_to_data
    from roc.ros.types import service_class

    type_name = expected.get("type", types[0])
    cls = service_class(type_name)
    request = fill_message(cls.Request, parse_values(expected.get("request"), f"{expectation.where}: request"))
    deadline = time.monotonic() + timeout
    for event in session.stream("call", {"service": expectation.name, "type": type_name, "request": encode(request)},
                                heartbeats=True):
        if event["event"] == "response":
            response = value_to_data(decode(cls.Response, event["data"]))
            mismatched = _mismatches(expected.get("response", {}), response)
            if mismatched:
                raise Failed(f"response {mismatched[0]}", response)
            return f"answered {to_yaml_line(response)}", response
        if time.monotonic() >= deadline:
            raise Failed(f"no response within {timeout:g} s")
    raise RocError("the call ended without a response")


def _mismatches(expected: dict[str, Any], actual: dict[str, Any], path: str = "") -> list[str]:
    """``field: value, expected value`` for each expected field that differs (nested tables compared
    field by field)."""
    found = []
    for key, want in expected.items():
        where = f"{path}{key}"
        if key not in actual:
            found.append(f"{where}: no such field")
        elif isinstance(want, dict) and isinstance(actual[key], dict):
            found += _mismatches(want, actual[key], f"{where}.")
        elif actual[key] != want:
            found.append(f"{where}: {to_yaml_line(actual[key])}, expected {to_yaml_line(want)}")
    return found


def _action(expectation: Expectation, session, _timeout: float, _window: float) -> tuple[str, Any]:
    actions = {a["name"]: a["types"] for a in _snapshot(session)["actions"]}
    if expectation.name not in actions:
        raise Failed(f"no action {expectation.name}")
    types = actions[expectation.name]
    if "type" in expectation.values and expectation.values["type"] not in types:
        raise Failed(f"type {', '.join(types)}, expected {expectation.values['type']}", types)
    return f"served ({', '.join(types)})", types


def _parameter(expectation: Expectation, session, _timeout: float, _window: float) -> tuple[str, Any]:
    node, want = expectation.values["node"], expectation.values["value"]
    try:
        value = session.query("param_get", {"node": node, "names": [expectation.name]})[0]
    except RocError as error:
        raise Failed(f"{node}: {error}") from None
    if value["type"] == "not set":
        raise Failed(f"not set, expected {to_yaml_line(want)}")
    if value["value"] != want:
        raise Failed(f"{to_yaml_line(value['value'])}, expected {to_yaml_line(want)}", value["value"])
    return to_yaml_line(value["value"]), value["value"]


PROBES: dict[str, Callable[[Expectation, Any, float, float], tuple[str, Any]]] = {
    "node": _node, "topic": _topic, "service": _service, "action": _action, "parameter": _parameter,
}
