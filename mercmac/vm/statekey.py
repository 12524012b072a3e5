"""The state key: which fields decide a part's future, declared on each field.

Fast-forward (vm/optimiser.py) compares the machine's state at each loop anchor and
skips passes only while it repeats; a field left out of that comparison by mistake
would make a skip silently inexact. So the machine and its parts are dataclasses whose
every field says in its metadata whether it is keyed (`key`, `part`) or why it may be
left out (`unkeyed`). `keyed` refuses a class with an unmarked field and derives from
the marks, once per class, STATE_KEY, NOT_KEYED and the function that builds the key:
generated code, as it runs at every loop anchor, not reflection per call.
tests/vm/test_vm_surface.py checks that every attribute of a live part is a marked field.
"""
from __future__ import annotations

from dataclasses import Field, field, fields
from operator import itemgetter
from typing import Callable

_KEY, _WHY, _AS, _OWN, _PART, _SHIFTS = "key", "why", "as", "own", "part", "shifts"


def key(as_: Callable | None = None, *, own: bool = False, shifts: bool = False,
        **options) -> Field:
    """A keyed field: its value, or `as_(value)` (a dict as its items, a chunk as its slot);
    with `own`, `as_(part, own)` (all RP counters but the jumping RP's own). `shifts`: a
    shifted pass (vm/skips.py) may differ in it by whole counts."""
    return field(metadata={_KEY: True, _AS: as_, _OWN: own, _SHIFTS: shifts}, **options)


def part(shifts: Callable | None = None, **options) -> Field:
    """A part of the machine (axis, clock, ...): keyed by the part's own state_key(). `shifts`:
    the part's `unshifted`, when its key holds fields that shift."""
    return field(metadata={_KEY: True, _PART: True, _SHIFTS: shifts}, **options)


def unkeyed(why: str, **options) -> Field:
    """A field left out of the key, with the reason a pass may differ in it and still
    repeat exactly."""
    if not why.strip():
        raise ValueError("an unkeyed field needs its reason")
    return field(metadata={_KEY: False, _WHY: why}, **options)


def _inline(expression: str) -> Callable[[Callable], Callable]:
    """Give an `as_` function the expression the generated key writes in its place ({} is
    the field): no call per field at every anchor."""
    def mark(function: Callable) -> Callable:
        function.inline = expression
        return function
    return mark


@_inline("tuple({}.items())")
def items(mapping: dict) -> tuple:
    """A dict's place in a key: its items, in their order (a key must not change with it)."""
    return tuple(mapping.items())


@_inline("tuple(sorted({}.items()))")
def sorted_items(mapping: dict) -> tuple:
    """A dict's items in key order, for a dict whose order is not part of its state."""
    return tuple(sorted(mapping.items()))


def keyed(method: str = "state_key") -> Callable[[type], type]:
    """Derive a dataclass's STATE_KEY, NOT_KEYED, its key function (named `method`) and, when
    fields shift, `unshifted(key)`, the key without them; refuse an unmarked field."""
    def derive(cls: type) -> type:
        marked = fields(cls)
        unmarked = [f.name for f in marked if _KEY not in f.metadata]
        if unmarked:
            raise TypeError(f"{cls.__name__}: mark {unmarked} with key(), part() or "
                            "unkeyed(why) (mercmac/vm/statekey.py)")
        keyed_fields = [f for f in marked if f.metadata[_KEY]]
        cls.STATE_KEY = tuple(f.name for f in keyed_fields)
        cls.NOT_KEYED = {f.name: f.metadata[_WHY] for f in marked if not f.metadata[_KEY]}
        setattr(cls, method, _key_function(cls.__qualname__, method, keyed_fields))
        shifts = [f.metadata.get(_SHIFTS) for f in keyed_fields]
        if any(shifts):
            cls.unshifted = staticmethod(_unshifted_function(shifts))
        return cls
    return derive


def _key_function(owner: str, name: str, keyed_fields: list[Field]) -> Callable:
    """`def name(self[, own]): return (self.a, as_b(self.b), self.c.state_key(), ...)`."""
    scope: dict = {}
    terms = [_term(f, f"_as{i}", scope) for i, f in enumerate(keyed_fields)]
    own = ", own" if any(f.metadata.get(_OWN) for f in keyed_fields) else ""
    exec(f"def {name}(self{own}):\n    return ({', '.join(terms)},)\n", scope)
    function = scope[name]
    function.__qualname__ = f"{owner}.{name}"
    function.__doc__ = f"{owner}'s state key: its fields {', '.join(f.name for f in keyed_fields)}."
    return function


def _term(f: Field, alias: str, scope: dict) -> str:
    """One field's place in the generated key."""
    m = f.metadata
    if m.get(_PART):
        return f"self.{f.name}.state_key()"
    if m[_AS] is None:
        return f"self.{f.name}"
    if hasattr(m[_AS], "inline"):
        return m[_AS].inline.format(f"self.{f.name}")
    scope[alias] = m[_AS]
    return f"{alias}(self, own)" if m[_OWN] else f"{alias}(self.{f.name})"


def _unshifted_function(shifts: list) -> Callable[[tuple], tuple]:
    """`unshifted(key)`: the key without the fields that shift (`shifts` True), each part that
    shifts (`shifts` its part's `unshifted`) unshifted alike; slices, as it runs at every anchor."""
    if not any(callable(s) for s in shifts):
        return itemgetter(*(i for i, s in enumerate(shifts) if not s))
    scope: dict = {}
    terms, start = [], 0
    for i, s in enumerate(shifts):
        if not s:
            continue
        if start < i:
            terms.append(f"key[{start}:{i}]")
        if callable(s):
            scope[f"_part{i}"] = s
            terms.append(f"(_part{i}(key[{i}]),)")
        start = i + 1
    if start < len(shifts):
        terms.append(f"key[{start}:]")
    exec(f"def unshifted(key):\n    return {' + '.join(terms)}\n", scope)
    return scope["unshifted"]
