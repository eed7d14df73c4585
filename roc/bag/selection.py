"""Which topics and services a recording or a conversion takes, with rosbag2's rules (its
TopicFilter): topics by name, type or regular expression (searched, not matched whole), services by
their event topics (``/svc/_service_event``), exclusions on top, hidden topics only when asked."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from roc.bag.metadata import SERVICE_EVENT_SUFFIX
from roc.errors import UsageError


def is_hidden(name: str) -> bool:
    """A topic with a name token that starts with ``_`` (as rcl's hidden topics)."""
    return any(token.startswith("_") for token in name.split("/") if token)


def is_service_event(name: str, type_name: str) -> bool:
    return name.endswith(SERVICE_EVENT_SUFFIX) and "/srv/" in type_name and type_name.endswith("_Event")


def event_topic(service: str) -> str:
    return service + SERVICE_EVENT_SUFFIX


def _compile(pattern: str, option: str) -> re.Pattern | None:
    if not pattern:
        return None
    try:
        return re.compile(pattern)
    except re.error as error:
        raise UsageError(f"{option}: '{pattern}' is not a valid regular expression ({error})") from None


@dataclass
class Selection:
    all_topics: bool = False
    all_services: bool = False
    topics: list[str] = field(default_factory=list)
    topic_types: list[str] = field(default_factory=list)
    services: list[str] = field(default_factory=list)  # service names
    regex: str = ""
    exclude_regex: str = ""
    exclude_topics: list[str] = field(default_factory=list)
    exclude_topic_types: list[str] = field(default_factory=list)
    exclude_services: list[str] = field(default_factory=list)
    include_hidden_topics: bool = False

    def __post_init__(self) -> None:
        self._include = _compile(self.regex, "--regex")
        self._exclude = _compile(self.exclude_regex, "--exclude-regex")
        self._services = {event_topic(s) for s in self.services}
        self._exclude_services = {event_topic(s) for s in self.exclude_services}

    @property
    def selects_anything(self) -> bool:
        return bool(self.all_topics or self.all_services or self.topics or self.topic_types or self.services
                    or self.regex)

    def takes(self, name: str, type_name: str) -> bool:
        if is_service_event(name, type_name):
            return self._takes_service(name)
        if not (self.all_topics or self.topics or self.topic_types or self.regex or self.include_hidden_topics):
            return False
        if not self.all_topics and name not in self.topics and type_name not in self.topic_types:
            if self._include is None or not self._include.search(name):
                return False
        if type_name in self.exclude_topic_types or name in self.exclude_topics:
            return False
        if self._exclude is not None and self._exclude.search(name):
            return False
        return self.include_hidden_topics or not is_hidden(name) or name in self.topics

    def _takes_service(self, name: str) -> bool:
        service = name[:-len(SERVICE_EVENT_SUFFIX)]
        if not (self.all_services or self._services or self._include):
            return False
        if not self.all_services and name not in self._services:
            if self._include is None or not self._include.search(service):
                return False
        if name in self._exclude_services:
            return False
        return not (self._exclude is not None and self._exclude.search(service))
