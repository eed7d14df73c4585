"""Name rules for new packages, nodes and libraries (REP 144), with a suggested fix."""

from __future__ import annotations

import keyword
import re

from roc.errors import UsageError

_VALID = re.compile(r"[a-z][a-z0-9_]*")
RULE = "lowercase letters, digits and underscores, starting with a letter, no '__', not ending with '_'"
# Names that cannot be a C++ namespace or a Python module, even though they follow REP 144.
_CPP_KEYWORDS = frozenset("""
alignas alignof and and_eq asm auto bitand bitor bool break case catch char char8_t char16_t char32_t class
compl concept const consteval constexpr constinit const_cast continue co_await co_return co_yield decltype
default delete do double dynamic_cast else enum explicit export extern false float for friend goto if inline
int long mutable namespace new noexcept not not_eq nullptr operator or or_eq private protected public register
reinterpret_cast requires return short signed sizeof static static_assert static_cast struct switch template
this thread_local throw true try typedef typeid typename union unsigned using virtual void volatile wchar_t
while xor xor_eq
""".split())


def is_valid_name(name: str) -> bool:
    return bool(_VALID.fullmatch(name)) and "__" not in name and not name.endswith("_")


def suggest_name(name: str) -> str:
    """The nearest valid name: ``My-Pkg`` and ``MyPkg`` become ``my_pkg`` (empty when there is none)."""
    spaced = re.sub(r"(?<=[a-z0-9])(?=[A-Z])", "_", name)
    words = re.sub(r"[^a-z0-9]+", "_", spaced.lower())
    return re.sub(r"_+", "_", words).lstrip("_0123456789").rstrip("_")


def _is_reserved(name: str) -> bool:
    return keyword.iskeyword(name) or name in _CPP_KEYWORDS


def check_name(kind: str, name: str) -> None:
    """Raise a usage error unless ``name`` is a valid ``kind`` name (package, node or library)."""
    suffix = "pkg" if kind == "package" else kind
    if not is_valid_name(name):
        suggestion = suggest_name(name)
        if _is_reserved(suggestion):
            suggestion = f"{suggestion}_{suffix}"
        hint = f"; try '{suggestion}'" if suggestion else ""
        raise UsageError(f"'{name}' is not a valid {kind} name ({RULE}){hint}")
    if _is_reserved(name):
        raise UsageError(f"'{name}' is a reserved word in Python or C++ and cannot be a {kind} name; "
                         f"try '{name}_{suffix}'")
