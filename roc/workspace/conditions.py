"""REP 149 ``condition`` attributes: tiny expressions such as ``$ROS_VERSION == 2 and $X != foo``.

Grammar (as in REP 149 / catkin_pkg): comparisons ``== != < <= > >=`` between ``$VARIABLES`` and
literals, combined with ``and``/``or`` and parentheses. An unset variable is the empty string.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

from roc.distribution import detected

# ROS 2 defaults, used when the environment does not set them (e.g. a Python venv with the ROS
# wheels, where no setup script has exported them); ROS_DISTRO's is that of the sourced ROS 2's rclpy.
DEFAULT_VARIABLES = {"ROS_VERSION": "2", "ROS_PYTHON_VERSION": "3"}

_TOKEN = re.compile(r"""\s*(?:(\()|(\))|(==|!=|<=|>=|<|>)|(\$\w+)|"([^"]*)"|'([^']*)'|([^\s()=!<>$"']+))""")
_COMPARE = {
    "==": lambda a, b: a == b,
    "!=": lambda a, b: a != b,
    "<": lambda a, b: a < b,
    "<=": lambda a, b: a <= b,
    ">": lambda a, b: a > b,
    ">=": lambda a, b: a >= b,
}


class ConditionError(ValueError):
    """The condition text is not a valid expression."""


def condition_environment(environ: Mapping[str, str]) -> dict[str, str]:
    """The variables conditions see: the environment over roc's ROS 2 defaults."""
    found = detected(environ) if environ.get("AMENT_PREFIX_PATH") and not environ.get("ROS_DISTRO") else None
    return {**DEFAULT_VARIABLES, **({"ROS_DISTRO": found[0]} if found else {}), **environ}


def evaluate_condition(text: str | None, variables: Mapping[str, str]) -> bool:
    """True when there is no condition or it holds for ``variables``."""
    if text is None or not text.strip():
        return True
    tokens = _tokenize(text)
    parser = _Parser(tokens, variables, text)
    value = parser.parse_or()
    if parser.pos != len(tokens):
        raise ConditionError(f"unexpected '{tokens[parser.pos][1]}' in condition '{text}'")
    return bool(value)


def _tokenize(text: str) -> list[tuple[str, str]]:
    tokens: list[tuple[str, str]] = []
    pos = 0
    text = text.rstrip()
    while pos < len(text):
        match = _TOKEN.match(text, pos)
        if not match or match.end() == pos:
            raise ConditionError(f"cannot parse condition '{text}' at column {pos + 1}")
        pos = match.end()
        lparen, rparen, op, var, double_quoted, single_quoted, word = match.groups()
        if lparen:
            tokens.append(("(", lparen))
        elif rparen:
            tokens.append((")", rparen))
        elif op:
            tokens.append(("op", op))
        elif var:
            tokens.append(("var", var[1:]))
        elif double_quoted is not None or single_quoted is not None:
            tokens.append(("lit", double_quoted if double_quoted is not None else single_quoted))
        elif word in ("and", "or"):
            tokens.append((word, word))
        else:
            tokens.append(("lit", word))
    return tokens


class _Parser:
    """Recursive descent: or_expr := and_expr ('or' and_expr)*; and_expr := atom ('and' atom)*."""

    def __init__(self, tokens: list[tuple[str, str]], variables: Mapping[str, str], text: str):
        self.tokens = tokens
        self.variables = variables
        self.text = text
        self.pos = 0

    def _peek(self) -> str | None:
        return self.tokens[self.pos][0] if self.pos < len(self.tokens) else None

    def _take(self, kind: str) -> str:
        if self._peek() != kind:
            found = self.tokens[self.pos][1] if self.pos < len(self.tokens) else "end of text"
            raise ConditionError(f"expected {kind} but found '{found}' in condition '{self.text}'")
        self.pos += 1
        return self.tokens[self.pos - 1][1]

    def parse_or(self) -> bool:
        value = self.parse_and()
        while self._peek() == "or":
            self.pos += 1
            right = self.parse_and()
            value = value or right
        return value

    def parse_and(self) -> bool:
        value = self.parse_atom()
        while self._peek() == "and":
            self.pos += 1
            right = self.parse_atom()
            value = value and right
        return value

    def parse_atom(self) -> bool:
        if self._peek() == "(":
            self.pos += 1
            value = self.parse_or()
            self._take(")")
            return value
        left = self._operand()
        op = self._take("op")
        right = self._operand()
        return _COMPARE[op](left, right)

    def _operand(self) -> str:
        kind = self._peek()
        if kind == "var":
            return self.variables.get(self._take("var"), "")
        if kind == "lit":
            return self._take("lit")
        found = self.tokens[self.pos][1] if self.pos < len(self.tokens) else "end of text"
        raise ConditionError(f"expected a $VARIABLE or a value but found '{found}' in condition '{self.text}'")
