"""``roc graph check --watch --prometheus PORT``: each probe's latest verdict and the graph figures it
measured, served as Prometheus metrics (prometheus-client) on http://ADDRESS:PORT/metrics."""

from __future__ import annotations

from typing import Any

from prometheus_client import CollectorRegistry, Gauge, start_http_server

from roc.engine.events import Event, ProbeResult, TaskFailed, TaskFinished

STATUS_VALUES = {"pass": 1.0, "fail": 0.0, "error": -1.0}


class PrometheusMetrics:
    """An event handler that keeps the gauges current; ``serve``/``close`` the HTTP endpoint."""

    def __init__(self) -> None:
        self.registry = CollectorRegistry()
        self.status = Gauge("roc_probe_status", "latest verdict: 1 pass, 0 fail, -1 error", ["probe", "kind"],
                            registry=self.registry)
        self.duration = Gauge("roc_probe_duration_seconds", "how long the probe took", ["probe"],
                              registry=self.registry)
        self.rate = Gauge("roc_topic_rate_hz", "publishing rate measured by a topic probe", ["topic"],
                          registry=self.registry)
        self.endpoints = Gauge("roc_topic_endpoints", "endpoints of a topic", ["topic", "side"],
                               registry=self.registry)
        self.rounds = Gauge("roc_check_rounds", "rounds of probes run", registry=self.registry)
        self.server: Any = None  # prometheus_client's WSGIServer while serving

    def serve(self, port: int, address: str = "127.0.0.1") -> None:
        self.server, _ = start_http_server(port, address, registry=self.registry)

    def close(self) -> None:
        if self.server is not None:
            self.server.shutdown()
            self.server.server_close()
            self.server = None

    def __call__(self, event: Event) -> None:
        if isinstance(event, ProbeResult):
            kind, _, name = event.task.partition(" ")
            self.status.labels(event.task, kind).set(STATUS_VALUES[event.status])
            measured = event.measured if isinstance(event.measured, dict) else {}
            if kind == "topic":
                if measured.get("rate") is not None:
                    self.rate.labels(name).set(measured["rate"])
                for side in ("publishers", "subscribers"):
                    if side in measured:
                        self.endpoints.labels(name, side).set(measured[side])
        elif isinstance(event, (TaskFinished, TaskFailed)):
            self.duration.labels(event.task).set(event.duration)
