"""Find Python-literal or JSON dictionaries in free LM text, never with ``eval``.

Accepted around and inside a dictionary: prose before and after, code fences, a variable assignment
(``motivations = {...}``), single or double or triple quotes, JSON ``true/false/null`` and Python
``True/False/None``, trailing commas, ``#`` and ``//`` comments, unquoted bare-word keys and values
(``{apple: mug}``), curly quotes, tuples and nested lists/dicts.

Order of attempts: ``json.loads`` and :func:`ast.literal_eval` of the whole (fence-stripped) answer, then
a scan for every top-level ``{`` parsed by a small tolerant recursive-descent parser.
"""

from __future__ import annotations

import ast
import json
import re
from typing import Any

from gift.core.errors import LMAnswerError

#: Answers longer than this are cut before scanning (the scan is linear per candidate brace).
MAX_CHARS = 200_000
MAX_DEPTH = 64

_FENCE = re.compile(r"^\s*```[A-Za-z0-9_+-]*\s*\n(.*?)\n?\s*```\s*$", re.S)
_ASSIGN = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)\s*(?::\s*[A-Za-z_][\w\[\], .]*)?=\s*$")
_QUOTES = {"'": "'", '"': '"', "\u201c": "\u201d", "\u2018": "\u2019"}
_CONSTANTS = {"true": True, "false": False, "null": None, "none": None, "nil": None}
_NUMBER = re.compile(r"[+-]?(?:\d[\d_]*\.?\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?|inf(?:inity)?|nan)",
                     re.I)
_BARE = re.compile(r"[A-Za-z_][\w\-./]*")


class _Fail(Exception):
    """Internal: the text at a position is not a literal."""


class _Parser:
    """Tolerant recursive-descent parser over ``text`` starting at a ``{``."""

    def __init__(self, text: str):
        self.s = text
        self.n = len(text)

    def skip(self, i: int) -> int:
        s, n = self.s, self.n
        while i < n:
            c = s[i]
            if c.isspace():
                i += 1
            elif c == "#" or s.startswith("//", i):
                j = s.find("\n", i)
                i = n if j < 0 else j + 1
            elif s.startswith("/*", i):
                j = s.find("*/", i + 2)
                if j < 0:
                    raise _Fail
                i = j + 2
            else:
                break
        return i

    def value(self, i: int, depth: int) -> tuple[Any, int]:
        if depth > MAX_DEPTH:
            raise _Fail
        i = self.skip(i)
        if i >= self.n:
            raise _Fail
        c = self.s[i]
        if c == "{":
            return self.mapping(i, depth)
        if c in "[(":
            return self.sequence(i, depth)
        if c in _QUOTES or (c in "rRuU" and i + 1 < self.n and self.s[i + 1] in "'\""):
            return self.strings(i)
        m = _NUMBER.match(self.s, i)
        if m and (m.end() == self.n or not (self.s[m.end()].isalnum() or self.s[m.end()] == "_")):
            return _number(m.group()), m.end()
        m = _BARE.match(self.s, i)
        if m:
            word = m.group()
            low = word.lower()
            if low in _CONSTANTS:
                return _CONSTANTS[low], m.end()
            return word, m.end()
        raise _Fail

    def strings(self, i: int) -> tuple[str, int]:
        """One string literal, or several adjacent ones concatenated (Python's implicit concatenation)."""
        out, i = self.string(i)
        while True:
            j = self.skip(i)
            if j < self.n and (self.s[j] in _QUOTES or (self.s[j] in "rRuU" and j + 1 < self.n
                                                       and self.s[j + 1] in "'\"")):
                more, i = self.string(j)
                out += more
            else:
                return out, i

    def string(self, i: int) -> tuple[str, int]:
        s, n = self.s, self.n
        raw = False
        if s[i] in "rRuU":
            raw = s[i] in "rR"
            i += 1
        q = s[i]
        close = _QUOTES[q]
        if q in "'\"" and s.startswith(q * 3, i):
            j = s.find(q * 3, i + 3)
            if j < 0:
                raise _Fail
            body = s[i + 3:j]
            return (body if raw else _unescape(body)), j + 3
        j = i + 1
        buf = []
        while j < n:
            c = s[j]
            if c == "\\" and not raw and j + 1 < n:
                buf.append(s[j:j + 2])
                j += 2
                continue
            if c == close:
                body = "".join(buf)
                return (body if raw else _unescape(body)), j + 1
            if c == "\n":
                raise _Fail
            buf.append(c)
            j += 1
        raise _Fail

    def sequence(self, i: int, depth: int) -> tuple[Any, int]:
        close = "]" if self.s[i] == "[" else ")"
        items: list[Any] = []
        i = self.skip(i + 1)
        while True:
            if i >= self.n:
                raise _Fail
            if self.s[i] == close:
                return (items if close == "]" else tuple(items)), i + 1
            v, i = self.value(i, depth + 1)
            items.append(v)
            i = self.skip(i)
            if i < self.n and self.s[i] == ",":
                i = self.skip(i + 1)
            elif i < self.n and self.s[i] != close:
                raise _Fail

    def mapping(self, i: int, depth: int) -> tuple[dict, int]:
        out: dict[Any, Any] = {}
        i = self.skip(i + 1)
        while True:
            if i >= self.n:
                raise _Fail
            if self.s[i] == "}":
                return out, i + 1
            k, i = self.value(i, depth + 1)
            if isinstance(k, (dict, list)):
                raise _Fail
            i = self.skip(i)
            if i >= self.n or self.s[i] not in ":=":
                raise _Fail
            v, i = self.value(i + 1, depth + 1)
            try:
                out[k] = v
            except TypeError:  # an unhashable key such as a tuple holding a list
                raise _Fail from None
            i = self.skip(i)
            if i < self.n and self.s[i] == ",":
                i = self.skip(i + 1)
            elif i < self.n and self.s[i] != "}":
                raise _Fail


def _number(tok: str) -> int | float:
    t = tok.replace("_", "")
    try:
        if re.fullmatch(r"[+-]?\d+", t):
            return int(t) if len(t) < 4000 else float(t)
        return float(t)
    except ValueError as e:  # pragma: no cover - the regex admits only valid numbers
        raise _Fail from e


_ESCAPES = {"n": "\n", "t": "\t", "r": "\r", "b": "\b", "f": "\f", "0": "\0", "\\": "\\", "'": "'",
            '"': '"', "/": "/", "\n": ""}
_HEX_WIDTH = {"x": 2, "u": 4, "U": 8}
_HEX = re.compile(r"[0-9a-fA-F]+")


def _unescape(body: str) -> str:
    """Resolve backslash escapes (``\\n``, ``\\'``, ``\\uXXXX``, ...); unknown ones stay as written."""
    if "\\" not in body:
        return body
    out, i, n = [], 0, len(body)
    while i < n:
        c = body[i]
        if c != "\\" or i + 1 >= n:
            out.append(c)
            i += 1
            continue
        e = body[i + 1]
        hexs = body[i + 2:i + 2 + _HEX_WIDTH.get(e, 0)]
        if e in _ESCAPES:
            out.append(_ESCAPES[e])
            i += 2
        elif e in _HEX_WIDTH and len(hexs) == _HEX_WIDTH[e] and _HEX.fullmatch(hexs) and int(hexs, 16) <= 0x10FFFF:
            out.append(chr(int(hexs, 16)))
            i += 2 + len(hexs)
        else:
            out.append(body[i:i + 2])
            i += 2
    return _join_pairs("".join(out))


def _join_pairs(text: str) -> str:
    """``text`` with UTF-16 surrogate pairs written as two ``\\u`` escapes (JSON's way to spell non-BMP
    characters) joined into one character; unchanged when it holds a lone surrogate."""
    try:
        return text.encode("utf-16", "surrogatepass").decode("utf-16")
    except UnicodeError:
        return text


def _joined(value: Any) -> Any:
    """A Python literal's strings (keys and values, nested) with :func:`_join_pairs` applied: Python, unlike
    JSON, keeps ``"\\ud800\\udc00"`` as two code points."""
    if isinstance(value, str):
        return _join_pairs(value)
    if isinstance(value, dict):
        return {_joined(k): _joined(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, set)):
        return type(value)(_joined(v) for v in value)
    return value


def _strip_fence(text: str) -> str:
    m = _FENCE.match(text)
    return m.group(1) if m else text


def _whole(text: str) -> dict | None:
    """The whole answer as JSON or a Python literal, when it is exactly one dictionary."""
    body = _strip_fence(text).strip()
    if not body.startswith("{"):
        return None
    try:
        d = json.loads(body)
    except (ValueError, RecursionError):
        try:
            d = _joined(ast.literal_eval(body))
        except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError):
            return None
    return d if isinstance(d, dict) else None


def _scan(text: str) -> list[tuple[int, int, dict]]:
    """Every top-level dictionary in ``text``: ``(start, end, value)`` in order."""
    found = []
    p = _Parser(text)
    i = text.find("{")
    while i >= 0:
        try:
            d, end = p.mapping(i, 0)
        except (_Fail, RecursionError):
            i = text.find("{", i + 1)
            continue
        found.append((i, end, d))
        i = text.find("{", end)
    return found


def _checked(text: Any) -> str:
    if not isinstance(text, str):
        raise LMAnswerError(f"expected the LM answer as text, got {type(text).__name__}", repr(text)[:2000])
    return text[:MAX_CHARS]


def extract_dicts(text: str) -> list[dict]:
    """Every top-level dictionary in the answer, in order (possibly empty)."""
    text = _checked(text)
    whole = _whole(text)
    if whole is not None:
        return [whole]
    return [d for _, _, d in _scan(text)]


def extract_dict(text: str) -> dict:
    """The last complete dictionary in the answer; :class:`LMAnswerError` (with the raw text) if none."""
    found = extract_dicts(text)
    if not found:
        raise LMAnswerError("no dictionary found in the LM answer (expected a Python or JSON dict such as "
                            "{'key': 'value'})", text if isinstance(text, str) else repr(text))
    return found[-1]


def extract_named_dicts(text: str) -> dict[str, dict]:
    """Dictionaries assigned to variables (``name = {...}``), by name; later assignments win."""
    text = _checked(text)
    out = {}
    for start, _, d in _scan(text):
        line_start = text.rfind("\n", 0, start) + 1
        m = _ASSIGN.search(text[line_start:start])
        if m:
            out[m.group(1)] = d
    return out
