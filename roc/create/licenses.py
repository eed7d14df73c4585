"""Licence texts for the LICENSE file of a new package, by SPDX id (stored in ``license_texts/``)."""

from __future__ import annotations

import datetime
from importlib import resources

DEFAULT = "TODO: License declaration"  # what ros2 pkg create writes when no licence is given
KNOWN = ("Apache-2.0", "BSD-2-Clause", "BSD-3-Clause", "BSL-1.0", "GPL-3.0-only", "LGPL-3.0-only", "MIT",
         "MIT-0", "MPL-2.0")
_PLACEHOLDER = "<year> <copyright holders>"  # the copyright line of the MIT and BSD texts


def canonical(license_id: str) -> str:
    """The known SPDX id spelled as SPDX does (``mit`` -> ``MIT``); other values unchanged."""
    return next((known for known in KNOWN if known.lower() == license_id.lower()), license_id)


def license_text(license_id: str, holder: str, year: int | None = None) -> str | None:
    """The full licence text with the copyright line filled in, or None for an unknown id."""
    if license_id not in KNOWN:
        return None
    text = resources.files("roc.create").joinpath("license_texts", f"{license_id}.txt").read_text()
    return text.replace(_PLACEHOLDER, f"{year or datetime.date.today().year} {holder}")
