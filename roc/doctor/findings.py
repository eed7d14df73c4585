"""A check's verdict (a Finding), and what a list of them adds up to."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

LEVELS = ("ok", "info", "warning", "error")


@dataclass
class Finding:
    """One thing a check found: ``level`` is ok, info (worth knowing, not wrong), warning or error;
    ``fix`` says what to do about a warning or an error."""

    category: str  # environment, network, graph
    check: str
    level: str
    message: str
    fix: str = ""
    details: dict[str, Any] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        return {key: value for key, value in asdict(self).items() if value or key == "level"}


def failed(finding: Finding, include_warnings: bool) -> bool:
    return finding.level == "error" or (include_warnings and finding.level == "warning")


def summary(findings: list[Finding], include_warnings: bool) -> dict[str, Any]:
    """The counts ros2 doctor prints: checks run, checks failed, the categories that failed."""
    checks: dict[tuple[str, str], bool] = {}
    for finding in findings:
        key = (finding.category, finding.check)
        checks[key] = checks.get(key, False) or failed(finding, include_warnings)
    failing = sorted({category for (category, _), bad in checks.items() if bad})
    return {"checks": len(checks), "failed": sum(checks.values()), "failed_categories": failing,
            "errors": sum(f.level == "error" for f in findings),
            "warnings": sum(f.level == "warning" for f in findings)}
