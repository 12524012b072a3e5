"""The fast JSON writer writes what `json.dumps(obj, indent=2)` writes, byte for byte."""
from __future__ import annotations

import json
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from mercmac.ops import TextEnum
from mercmac.render import jsontext


class Colour(TextEnum):
    RED = "red"


scalars = st.one_of(st.none(), st.booleans(), st.integers(-2**70, 2**70),
                    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=8),
                    st.just(Colour.RED))
keys = st.one_of(st.text(max_size=6), st.integers(-5, 5), st.booleans(), st.none(),
                 st.floats(allow_nan=False, width=16))
documents = st.recursive(
    scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=5), st.tuples(inner, inner),
                            st.dictionaries(keys, inner, max_size=5)),
    max_leaves=40)


@settings(max_examples=budget(500))
@given(documents)
def test_it_writes_what_json_dumps_writes(document):
    assert jsontext.dumps(document) == json.dumps(document, indent=2)


def test_a_list_of_records_and_the_empty_ones():
    document = {"events": [{"t_ms": 0.5, "kind": Colour.RED, "slot": None, "ok": True}] * 3,
                "none": [], "nothing": {}, "deep": [[{"a": [{}]}]], "inf": -math.inf}
    assert jsontext.dumps(document) == json.dumps(document, indent=2)


def test_what_json_refuses_it_refuses():
    with pytest.raises(TypeError):
        jsontext.dumps({"a": object()})
    with pytest.raises(TypeError):
        jsontext.dumps([{"a": {1, 2}}])
    with pytest.raises(TypeError):
        jsontext.dumps({(1, 2): 3})
