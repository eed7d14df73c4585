"""The one way roc renders files from Jinja templates: strict (an undefined name is an error), text
kept as written (no HTML escaping, trailing newline kept)."""

from __future__ import annotations

from collections.abc import Callable


def template_environment(package: str, filters: dict[str, Callable[[object], str]], **options):
    """A Jinja environment over ``<package>/templates`` with the given filters."""
    import jinja2

    environment = jinja2.Environment(
        loader=jinja2.PackageLoader(package, "templates"), keep_trailing_newline=True,
        undefined=jinja2.StrictUndefined, autoescape=False, **options,
    )
    environment.filters.update(filters)
    return environment
