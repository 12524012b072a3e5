"""JSON text as `json.dumps(obj, indent=2)` writes it, byte for byte, faster.

With an indent the standard library leaves its C encoder for a pure-Python generator; a
simulation's JSON lists up to 10,000 entries in each of four lists
(docs/simulator.md, "What sim writes"), and writing them that way once took longer than
simulating 1500 days. Here each value is written by one recursive function into a list of
strings, scalars through the C string encoder.
tests/render/test_jsontext.py compares the two on random documents.
"""
from __future__ import annotations

import json
from functools import lru_cache
from json.encoder import c_make_encoder
from json.encoder import encode_basestring_ascii as _string  # the C one, as json.dumps uses

INDENT = "  "
_NESTED = (dict, list, tuple)


def dumps(obj: object) -> str:
    """`json.dumps(obj, indent=2)` (ensure_ascii, NaN allowed, keys as json converts them)."""
    out: list[str] = []
    _write(obj, out, "\n")
    return "".join(out)


@lru_cache(maxsize=None)
def _flat(inner: str):
    """The encoder writing a flat object's members one to a line, indented by `inner`: the C
    one made once (JSONEncoder.encode makes one per call), else the standard library's."""
    if c_make_encoder is None:  # a Python without the _json accelerator
        encoder = json.JSONEncoder(separators=("," + inner, ": "))
        return lambda o: encoder.encode(o)
    made = c_make_encoder(None, _unserializable, _string, None, ": ", "," + inner, False, False,
                          True)
    return lambda o: "".join(made(o, 0))


@lru_cache(maxsize=4096)
def _flat_types(types: tuple[type, ...]) -> bool:
    """Whether values of these types are all scalars (no object or array inside)."""
    return not any(issubclass(t, _NESTED) for t in types)


def _unserializable(o: object) -> None:
    raise TypeError(f"Object of type {type(o).__name__} is not JSON serializable")


def _flat_object(v: object) -> bool:
    """A non-empty object of scalars only."""
    return type(v) is dict and bool(v) and _flat_types(tuple(map(type, v.values())))


def _write(o: object, out: list[str], nl: str) -> None:
    if not isinstance(o, _NESTED):
        out.append(_scalar(o))
        return
    if not o:
        out.append("{}" if isinstance(o, dict) else "[]")
        return
    inner = nl + INDENT
    if isinstance(o, dict):
        if _flat_object(o):  # the C encoder writes the members, keys as json.dumps does
            out.append("{" + inner + _flat(inner)(o)[1:-1] + nl + "}")
            return
        items, opening, closing = o.items(), "{", "}"
    else:
        if all(map(_flat_object, o)):  # a list of records (a simulation's events)
            out.append(_records(o, nl, inner, inner + INDENT))
            return
        items, opening, closing = ((None, v) for v in o), "[", "]"
    sep = opening + inner
    for k, v in items:
        out.append(sep)
        if opening == "{":
            out.append(_string(k) if isinstance(k, str) else _key(k))
            out.append(": ")
        _write(v, out, inner)
        sep = "," + inner
    out.append(nl + closing)


def _records(o: list | tuple, nl: str, inner: str, members: str) -> str:
    """A list of flat objects (a simulation's events): written by the C encoder in one call,
    every separator the members' one, then each "}" + separator + "{" between two objects
    made the list's. A string cannot hide that sequence: the encoder escapes a newline, and
    a scalar member ends with a quote, a digit or a letter, never with "}"."""
    text = _flat(members)(o)  # "[{" m1 "}," members "{" m2 "}]"
    between = "}," + members + "{"
    return ("[" + inner + "{" + members
            + text[2:-2].replace(between, inner + "}," + inner + "{" + members)
            + inner + "}" + nl + "]")


def _scalar(v: object) -> str:
    if isinstance(v, str):
        return _string(v)
    if v is None:
        return "null"
    if v is True:
        return "true"
    if v is False:
        return "false"
    if isinstance(v, int):
        return int.__repr__(v)
    if isinstance(v, float):
        return _float(v)
    raise TypeError(f"Object of type {type(v).__name__} is not JSON serializable")


def _float(v: float) -> str:
    if v != v:
        return "NaN"
    if v == float("inf"):
        return "Infinity"
    if v == -float("inf"):
        return "-Infinity"
    return float.__repr__(v)


def _key(k: object) -> str:
    """A key json.dumps turns into a string: a number, a boolean or null, written as one."""
    if k is None or isinstance(k, (int, float)):
        return '"' + _scalar(k) + '"'
    raise TypeError(f"keys must be str, int, float, bool or None, not {type(k).__name__}")
