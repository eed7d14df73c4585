"""DDS content filters (``--content-filter EXPR --content-filter-params P...``) without rclpy: the
filter expression grammar of the DDS specification (annex B, as Fast DDS reads it) parsed, checked
against a message type, and evaluated on message objects.

The middleware evaluates a filter where it can (roc.ros.raw_subscription hands it the expression and
``ContentFilter.parameters``); this module is what roc checks first, so that a bad filter is one line
naming what is wrong before anything subscribes, and what roc filters with where the middleware cannot.

Conditions: ``NOT``, ``AND``, ``OR`` and parentheses over comparisons of a field with a literal, a
parameter (``%0`` .. ``%99``) or another field: ``=``, ``<>`` (``!=``), ``<``, ``<=``, ``>``, ``>=``,
``LIKE`` (``%`` any text, ``_`` one character) and ``MATCH`` (a regular expression) on strings, and
``field [NOT] BETWEEN low AND high``. Fields are paths: ``header.frame_id``, ``points[0].x``.
Literals: integers (also ``0x`` hexadecimal), floats, ``'strings'``, ``TRUE``/``FALSE``. A
parameter is a literal too; one that is none (a bare word) is taken as a string and handed to the
middleware quoted, since Fast DDS refuses an unquoted string parameter without saying so."""

from __future__ import annotations

import functools
import operator
import re
from dataclasses import dataclass
from typing import Any

from roc.errors import UsageError

_TOKEN = re.compile(r"""\s*(?:
    (?P<float>[-+]?(?:\d+\.\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?\d+[eE][-+]?\d+)
  | (?P<hex>[-+]?0[xX][0-9a-fA-F]+)
  | (?P<integer>[-+]?\d+)
  | (?P<string>[`']([^']*)')
  | (?P<parameter>%\d{1,2})
  | (?P<op><>|!=|<=|>=|=|<|>)
  | (?P<punct>[()])
  | (?P<word>[A-Za-z_][A-Za-z0-9_]*(?:\s*(?:\.\s*[A-Za-z_][A-Za-z0-9_]*|\[\s*\d+\s*\]))*)
)""", re.VERBOSE)
KEYWORDS = {"AND", "OR", "NOT", "BETWEEN", "LIKE", "MATCH", "TRUE", "FALSE"}
COMPARISONS = {"=", "<>", "!=", "<", "<=", ">", ">=", "LIKE", "MATCH"}
NUMBER, STRING, BOOLEAN = "number", "string", "boolean"
_NUMBER_TYPES = {"byte", "octet", "char", "float", "double", "long double", "int8", "uint8", "int16", "uint16",
                 "int32", "uint32", "int64", "uint64"}


class ContentFilterError(UsageError):
    """A filter expression or parameter that cannot be used: names the option and what is wrong."""

    def __init__(self, message: str) -> None:
        super().__init__(f"--content-filter: {message}")


@dataclass(frozen=True)
class Field:
    path: tuple[str | int, ...]  # names and indices

    @property
    def text(self) -> str:
        return "".join(f"[{part}]" if isinstance(part, int) else f".{part}" for part in self.path).lstrip(".")


@dataclass(frozen=True)
class Literal:
    value: Any
    kind: str  # NUMBER, STRING or BOOLEAN


@dataclass(frozen=True)
class Parameter:
    index: int


@dataclass(frozen=True)
class Comparison:
    left: Field | Literal | Parameter
    op: str
    right: Field | Literal | Parameter


@dataclass(frozen=True)
class Between:
    field: Field
    low: Literal | Parameter
    high: Literal | Parameter
    negated: bool


@dataclass(frozen=True)
class Logical:
    op: str  # AND, OR, NOT
    operands: tuple


def _quoted(text: str) -> str:
    """Part of a filter for a message: in double quotes, since its strings are in single ones."""
    return f"'{text}'" if '"' in text else f'"{text}"'


def _place(text: str, position: int, found: str) -> str:
    """Where an error is in expression ``text``: ``found``, at ``position``, and which character that is."""
    if position >= len(text.rstrip()):
        return f"the end of {_quoted(text)}"
    return f"{_quoted(found)} (character {position + 1}) in {_quoted(text)}"


def _tokens(text: str) -> list[tuple[str, str, int]]:
    """(kind, value, the position it starts at) of each token."""
    tokens, position = [], 0
    while position < len(text.rstrip()):
        match = _TOKEN.match(text, position)
        if match is None or match.end() == position:
            rest = text[position:].lstrip()
            raise ContentFilterError(f"cannot read {_place(text, len(text) - len(rest), rest.split()[0])}")
        kind = match.lastgroup or ""
        value, start = match.group(kind), match.start(kind)
        if kind == "word" and value.upper() in KEYWORDS:
            kind, value = "keyword", value.upper()
        tokens.append((kind, value, start))
        position = match.end()
    return tokens


def literal(text: str) -> Literal | None:
    """A literal's value, or None when ``text`` is no literal."""
    try:
        tokens = _tokens(text) if text.strip() else []
    except ContentFilterError:
        return None
    if len(tokens) != 1:
        return None
    kind, value, _ = tokens[0]
    if kind in ("integer", "hex"):
        return Literal(int(value, 0 if kind == "hex" else 10), NUMBER)
    if kind == "float":
        return Literal(float(value), NUMBER)
    if kind == "string":
        return Literal(value[1:-1], STRING)
    if kind == "keyword" and value in ("TRUE", "FALSE"):
        return Literal(value == "TRUE", BOOLEAN)
    return None


class _Parser:
    def __init__(self, text: str) -> None:
        self.text, self.tokens, self.at = text, _tokens(text), 0

    def peek(self) -> tuple[str, str]:
        return self.tokens[self.at][:2] if self.at < len(self.tokens) else ("end", "")

    def place(self) -> str:
        """Where the next token is, for an error: ``"x" (character 7) in "..."`` or ``the end of "..."``."""
        if self.at == len(self.tokens):
            return _place(self.text, len(self.text), "")
        _, value, position = self.tokens[self.at]
        return _place(self.text, position, value)

    def take(self, kind: str, value: str | None = None) -> str:
        found = self.peek()
        if found[0] != kind or (value is not None and found[1] != value):
            raise ContentFilterError(f"expected {value or kind} at {self.place()}")
        self.at += 1
        return found[1]

    def condition(self) -> Any:
        return self._joined("OR", self.conjunction)

    def conjunction(self) -> Any:
        return self._joined("AND", self.negation)

    def _joined(self, op: str, operand: Any) -> Any:
        """``operand (op operand)*``: one operand alone, or their Logical."""
        operands = [operand()]
        while self.peek() == ("keyword", op):
            self.at += 1
            operands.append(operand())
        return operands[0] if len(operands) == 1 else Logical(op, tuple(operands))

    def negation(self) -> Any:
        if self.peek() == ("keyword", "NOT"):
            self.at += 1
            return Logical("NOT", (self.negation(),))
        if self.peek() == ("punct", "("):
            self.at += 1
            inner = self.condition()
            self.take("punct", ")")
            return inner
        return self.predicate()

    def operand(self) -> Field | Literal | Parameter:
        kind, value = self.peek()
        if kind == "word":
            self.at += 1
            parts = re.findall(r"[A-Za-z_][A-Za-z0-9_]*|\d+", value)
            return Field(tuple(int(part) if part.isdigit() else part for part in parts))
        if kind == "parameter":
            self.at += 1
            return Parameter(int(value[1:]))
        found = literal(value) if kind != "keyword" or value in ("TRUE", "FALSE") else None
        if found is None:
            raise ContentFilterError(f"expected a field, a value or a parameter at {self.place()}")
        self.at += 1
        return found

    def predicate(self) -> Comparison | Between:
        left = self.operand()
        negated = self.peek() == ("keyword", "NOT")
        if negated:
            self.at += 1
        if self.peek() == ("keyword", "BETWEEN"):
            self.at += 1
            low = self.operand()
            self.take("keyword", "AND")
            high = self.operand()
            if not isinstance(left, Field) or isinstance(low, Field) or isinstance(high, Field):
                raise ContentFilterError(f"BETWEEN takes a field and two values, in {_quoted(self.text)}")
            return Between(left, low, high, negated)
        if negated:
            raise ContentFilterError(f"expected BETWEEN after NOT at {self.place()}")
        kind, op = self.peek()
        if kind not in ("op", "keyword") or op not in COMPARISONS:
            raise ContentFilterError(f"expected a comparison (=, <>, <, <=, >, >=, LIKE, MATCH, BETWEEN) "
                                     f"at {self.place()}")
        self.at += 1
        right = self.operand()
        if not isinstance(left, Field) and not isinstance(right, Field):
            raise ContentFilterError(f"each comparison needs a field, in {_quoted(self.text)}")
        return Comparison(left, "<>" if op == "!=" else op, right)


def _kind_of(slot: Any) -> str | None:
    """NUMBER, STRING or BOOLEAN for a rosidl basic or string type; None for anything else."""
    from rosidl_parser import definition as idl

    if isinstance(slot, (idl.AbstractString, idl.AbstractWString)):
        return STRING
    if isinstance(slot, idl.BasicType):
        return BOOLEAN if slot.typename == "boolean" else NUMBER if slot.typename in _NUMBER_TYPES else None
    return None


def _field_kind(cls: Any, field: Field) -> str:
    """The kind of the value at ``field`` in messages of ``cls``; ContentFilterError when there is none."""
    from rosidl_parser import definition as idl

    from roc.ros.messages import fields
    from roc.ros.types import resolve_type

    slot: Any = None
    for part in field.path:
        if isinstance(part, int):
            if not isinstance(slot, idl.AbstractNestedType):
                raise ContentFilterError(f"'{field.text}': [{part}] indexes a field that is not an array")
            slot = slot.value_type
        else:
            if slot is not None:
                if not isinstance(slot, idl.NamespacedType):
                    raise ContentFilterError(f"'{field.text}': '{part}' is a field of a field that has none")
                cls = resolve_type("/".join(slot.namespaced_name()))
            found = dict(fields(cls))
            if part not in found:
                raise ContentFilterError(f"'{field.text}': {cls.__name__} has no field '{part}' "
                                         f"(it has {', '.join(found) or 'none'})")
            slot = found[part]
    kind = _kind_of(slot)
    if kind is None:
        raise ContentFilterError(f"'{field.text}' is not a number, string or boolean: compare one of its fields")
    return kind


class ContentFilter:
    """A parsed filter: ``check(cls)`` against a message class, ``accepts(message)`` to evaluate it."""

    def __init__(self, expression: str, parameters: list[str] | None = None) -> None:
        self.expression = expression
        if not expression.strip():
            raise ContentFilterError("the expression is empty")
        parser = _Parser(expression)
        self._tree = parser.condition()
        if parser.peek()[0] != "end":
            raise ContentFilterError(f"unexpected {parser.place()}")
        if len(parameters or []) > 100:
            raise ContentFilterError("at most 100 parameters (%0 to %99)")
        self._values = [literal(text) or Literal(text, STRING) for text in parameters or []]
        # What the middleware gets: each parameter a literal (a bare word quoted as a string).
        self.parameters = [text if literal(text) else "'" + text + "'" for text in parameters or []]
        for index in _parameters(self._tree):
            if index >= len(self._values):
                raise ContentFilterError(f"{_quoted(expression)} uses %{index} but {len(self._values)} parameter(s) "
                                         "were given (--content-filter-params)")
        if any("'" in value.value for value in self._values if value.kind == STRING):
            raise ContentFilterError("a string parameter may not hold a quote (')")

    def _value(self, operand: Field | Literal | Parameter) -> Literal:
        return self._values[operand.index] if isinstance(operand, Parameter) else operand  # type: ignore[return-value]

    def check(self, cls: Any) -> None:
        """ContentFilterError when a field is not in ``cls`` or is compared with a value of another kind."""
        for node in _predicates(self._tree):
            if isinstance(node, Between):
                kinds = [_field_kind(cls, node.field), self._value(node.low).kind, self._value(node.high).kind]
                text = f"{node.field.text} BETWEEN"
            else:
                kinds = [_field_kind(cls, side) if isinstance(side, Field) else self._value(side).kind
                         for side in (node.left, node.right)]
                text = node.op
                if node.op in ("LIKE", "MATCH") and kinds != [STRING, STRING]:
                    raise ContentFilterError(f"{node.op} compares strings, in {_quoted(self.expression)}")
                if node.op == "MATCH" and not isinstance(node.right, Field):
                    try:
                        _pattern("MATCH", self._value(node.right).value)
                    except re.error as error:
                        raise ContentFilterError(f"MATCH: not a regular expression ({error})") from None
            if len(set(kinds)) != 1:
                other = next(kind for kind in kinds if kind != kinds[0])
                raise ContentFilterError(f"{text} compares a {kinds[0]} with a {other}, in {_quoted(self.expression)}")

    def accepts(self, message: Any) -> bool:
        return self._evaluate(self._tree, message)

    def _evaluate(self, node: Any, message: Any) -> bool:
        if isinstance(node, Logical):
            if node.op == "NOT":
                return not self._evaluate(node.operands[0], message)
            results = (self._evaluate(operand, message) for operand in node.operands)
            return all(results) if node.op == "AND" else any(results)
        if isinstance(node, Between):
            value = _read(message, node.field)
            inside = self._value(node.low).value <= value <= self._value(node.high).value
            return inside != node.negated
        left, right = (_read(message, side) if isinstance(side, Field) else self._value(side).value
                       for side in (node.left, node.right))
        return _compare(left, node.op, right)


def _parameters(node: Any) -> list[int]:
    return [side.index for predicate in _predicates(node)
            for side in ((predicate.left, predicate.right) if isinstance(predicate, Comparison)
                         else (predicate.low, predicate.high)) if isinstance(side, Parameter)]


def _predicates(node: Any) -> list[Comparison | Between]:
    if isinstance(node, Logical):
        return [found for operand in node.operands for found in _predicates(operand)]
    return [node]


def _read(message: Any, field: Field) -> Any:
    value = message
    for part in field.path:
        value = value[part] if isinstance(part, int) else getattr(value, part)
    if isinstance(value, bytes):  # a byte field
        return int.from_bytes(value, "little")
    return value.item() if hasattr(value, "item") else value  # a numpy scalar of an array


@functools.lru_cache(maxsize=64)
def _pattern(op: str, pattern: str) -> re.Pattern:
    """MATCH's regular expression, or LIKE's pattern as one (``%`` any text, ``_`` one character)."""
    if op == "MATCH":
        return re.compile(pattern)
    return re.compile("".join(".*" if c == "%" else "." if c == "_" else re.escape(c) for c in pattern), re.DOTALL)


_OPERATORS = {"=": operator.eq, "<>": operator.ne, "<": operator.lt, "<=": operator.le, ">": operator.gt,
              ">=": operator.ge}


def _compare(left: Any, op: str, right: Any) -> bool:
    if op in ("LIKE", "MATCH"):
        return _pattern(op, right).fullmatch(left) is not None
    return bool(_OPERATORS[op](left, right))
