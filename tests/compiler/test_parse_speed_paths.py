"""The two readings of a file give one result (once a 500 KB line took 67-81 s to `check`).

`parse.read` builds the AST while it reads a file that parses; lark's parser, its tree and
the Transformer read every other file (they recover from syntax errors). Both
must give the same AST, spans included, and the same diagnostics; `read` may decline a
file only where lark's reading reports something. The golden file pins what the reading
before `read` (lark's parse, then the Transformer: commit 412d0a7) made of the examples
(kept in the file as they were), the hostile texts and seeded mutations of both: the AST,
the broken lines and the syntax errors (the checks after it are the same code for both
readings, compared in-process below; syntax errors by rule and line only, so that a better
message is not a different reading). It was written by running this file in a worktree
of that commit: `MERCMAC_UPDATE_GOLDEN=1 pytest tests/compiler/test_parse_speed_paths.py -k golden`.
"""
from __future__ import annotations

import hashlib
import json
import os
import random
import re
from unittest import mock

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers import paths
from helpers.budgets import budget
from helpers.paths import EXAMPLE_FILES
from mercmac.compiler import ast_builder, compile_source
from mercmac.compiler.ast_builder import build
from mercmac.compiler.parse import MAX_NESTING, parse_partial
from mercmac.diagnostics import Report
from mercmac.source import Source

GOLDEN = paths.GOLDEN / "parse-paths.json"
EXAMPLE_TEXTS = {p.name: p.read_text(encoding="utf-8") for p in EXAMPLE_FILES}
NOISE = (list("[]{},@=-+?0123456789 \t\n\r\f.MCEWXNFRPSVTabcdefmnorstw/_")
         + ["when ", "and ", "not ", "macro ", "repeat ", "every ", "ms", "call ", "goto ",
            "const ", "target ", "C-863", "autostart", "//", "[MC05]", "\r\n", "}\n", "{\n",
            "\x00", "\u2122", "99999999999999", "5.5 s", "@3 "])


def _nested(depth: int, end: str = "\n") -> str:
    body = "MR 1"
    for level in range(depth):
        body = f"when {level % 8 + 1} {{{end}  {body}{end}}} MR 1"
    return f"macro a {{ {body} }}{end}autostart {{ call a }}{end}"


HOSTILE = {
    "empty": "",
    "blank lines": "\n\n  \n\t\n",
    "comments only": "// one\n  // two\r\n// three",
    "form feeds": "\fmacro a {\f MR 1 \f}\f\n",
    "one-macro line": "target C-863\nmacro m { " + ",".join(["MR 1"] * 3000) + " }\n"
                      "autostart { call m }\n",
    "raw long line": "[MC01] " + "XF1," * 2000 + "TP\n",
    "raw broken line": "[MC01] MR5000 WS100\n[MC02] TP\n",
    "3k repeat 1": "macro a { " + ", ".join(["repeat 1 { TP }"] * 3000) + " }\n",
    "nested 32": _nested(MAX_NESTING),  # the deepest the controller holds
    "nested 33": _nested(MAX_NESTING + 1),  # reported: `read` declines it
    "nested 40 CRLF": _nested(40, "\r\n"),
    "nested 300": _nested(300),
    "CR only": "macro a @20 { MR 5 }   // c\rautostart { call a }\r[MC05] MR 9\r",
    "mixed ends": "target C-863\r\nconst A = 5\rmacro a {\n MR A\r\n WS 10 }\r"
                  "autostart {\r call a }",
    "missing brace at end": "macro a {\n  MR 1\n  when 1 {\n    TP\n",
    "broken lines": "macro a {\n  MR 1 2\n  whne 1 {\n  TP\n  }\n}\nautostart { call a }\n",
    "outside": "MR5000\ntarget C-863\nconst A = 1\nTP\n",
    "NUL": "macro a { MR 1 }\x00\n",
    "non-ascii": "macro a { MR 1 }\nmacro \u00e9 { TP }\n",
    "keywords": "const and_more = 3\nmacro not_x @ 7 { when not 1 and 2 { call not_x } "
                "every 1.5 s { FA? } every and_more { SV FAST } repeat and_more { goto not_x } }\n",
    "big numbers": "const A = 99999999999999999\n"
                   "macro a @ 99999999999 { MR +  5, MR -99999999999999 }\n",
    "durations": "macro a { every 20ms { TP } every 0.5 s { TP } every 3 min { TP } "
                 "every 99999999999 d { TP } every 1.0005 s { TP } }\n",
    "target spans lines": "target c863\n\n\n   const B=1\n\n",
}


# What moves the code without breaking it, as often as not: the spans change.
BLANKS = [" ", "\t", "\n", "\r\n", "\r", "\f", "// note\n", "  \n\n"]


def mutate(text: str, rng: random.Random) -> str:
    """TEXT with a few places replaced by noise or blanks, and sometimes other line ends."""
    for _ in range(rng.randint(1, 3)):
        at, cut = rng.randint(0, len(text)), rng.randint(0, 5)
        noise = "".join(rng.choice(NOISE) for _ in range(rng.randint(0, 4)))
        if rng.random() < 0.5:
            cut, noise = 0, rng.choice(BLANKS)
        text = text[:at] + noise + text[at + cut:]
    if rng.random() < 0.2:
        text = text.replace("\n", rng.choice(["\r\n", "\r"]))
    return text


def _diagnostics(report: Report) -> list:
    """The syntax errors as rule and line: their wording and columns may improve (the
    hints for natural guesses point at the guessed word) without the reading changing."""
    return [(d.rule.code, str(d.severity), d.span.line) for d in report.items]


def _parse_module(text: str, report: Report):
    """Parsed with the AST as its tree, as the compiler reads a file."""
    try:
        from mercmac.compiler.ast_builder import parse_module
    except ImportError:  # the reading before `read` (the golden file's commit)
        parsed = parse_partial(text, report)
        return parsed if parsed.tree is None else parsed._replace(tree=build(parsed.tree))
    return parse_module(text, report)


def outcome(text: str) -> str:
    """A digest of what the parser makes of TEXT: the AST with its spans (repr names each
    node's type), the broken lines and the syntax errors."""
    report = Report("t.mcm")
    parsed = _parse_module(text, report)
    module = parsed.tree
    if module is not None and hasattr(ast_builder, "parse_module"):  # (not at the golden's commit)
        module = _as_before(module, text)
    tree = repr(module).replace(", sign=''", "")  # a name without a sign, as it was
    found = [tree, sorted(parsed.broken), parsed.failed, _diagnostics(report)]
    return hashlib.sha256(json.dumps(found).encode()).hexdigest()[:16]  # 64 bits: enough


# The reading before ended a `const` or `target` statement's span past its newline and the
# blank lines after it (grammar.lark's _NL), so an editor underlined the next line; it ends
# at its last token since. What lies between: blanks, a comment, then the newlines.
_NL_AFTER = re.compile(r"[ \t\f]*(?://[^\n]*)?((?:\n[ \t]*)+)")
_AT_END = re.compile(r"[ \t\f]*(?://[^\n]*)?\Z")


def _recovered_one_liner(text: str) -> bool:
    """A text with syntax errors that holds `const` or `target`: lark's recovery gave such a
    statement's span the token after its error, which `_as_before` cannot tell again (the
    in-process comparisons below still hold both readings to one result)."""
    report = Report("t.mcm")
    return _parse_module(text, report).failed and re.search(r"\b(const|target)\b", text) is not None


def _as_before(module, text: str):
    """MODULE with its const and target spans as the reading before made them."""
    from mercmac.compiler import ast
    from mercmac.source import Span, to_lf

    lf = to_lf(text)
    starts = [0] + [m.end() for m in re.finditer("\n", lf)]
    items = []
    for item in module.items:
        if isinstance(item, (ast.Const, ast.Target)):
            s = item.span
            at = starts[s.end_line - 1] + s.end_column - 1
            found = _NL_AFTER.match(lf, at)
            if found is not None:
                end = found.end()
                line = lf.count("\n", 0, end) + 1
                column = end - starts[line - 1] + 1
                if end == len(lf):  # and the newline the reading adds at the end of the text
                    line, column = line + 1, 1
                item = item._replace(span=Span(s.line, s.column, line, column))
            elif _AT_END.match(lf, at):  # the newline the reading adds at the end of the text
                item = item._replace(span=Span(s.line, s.column, s.end_line + 1, 1))
        items.append(item)
    return module._replace(items=tuple(items))


def golden_cases(examples: dict[str, str]) -> dict[str, str]:
    """The examples, the hostile texts and 40 seeded mutations of each of them."""
    cases = {**{f"example {k}": v for k, v in examples.items()},
             **{f"hostile {k}": v for k, v in HOSTILE.items()}}
    for name, text in list(cases.items()):
        rng = random.Random(name)
        for n in range(40 if len(text) < 20_000 else 4):
            cases[f"{name} #{n}"] = mutate(text, rng)
    return cases


@pytest.mark.slow
def test_golden_outcomes_of_the_reading_before():
    """The examples as they were then are kept in the golden file: editing one breaks nothing."""
    if os.environ.get("MERCMAC_UPDATE_GOLDEN"):
        cases = golden_cases(EXAMPLE_TEXTS)
        found = {name: outcome(text) for name, text in cases.items()}
        GOLDEN.write_text(json.dumps({"examples": EXAMPLE_TEXTS, "outcomes": found}, indent=0,
                                     sort_keys=True) + "\n", encoding="utf-8")
    expected = json.loads(GOLDEN.read_text(encoding="utf-8"))
    cases = golden_cases(expected["examples"])
    assert set(expected["outcomes"]) == set(cases), "HOSTILE changed: regenerate (see the top)"
    differ = [(name, text[:300]) for name, text in sorted(cases.items())
              if outcome(text) != expected["outcomes"][name] and not _SIGNED_NAME.search(text)
              and not _recovered_one_liner(text)]
    assert not differ


# Read otherwise on purpose since: a sign before a name is a const's value signed (`MR -FAR`,
# docs/language.md), where a sign before a letter was a syntax error.
_SIGNED_NAME = re.compile(r"[+-][ \t]*[A-Za-z_]")


def both_readings(text: str):
    """(what `read` builds, lark's reading: its AST, whether it reported anything)."""
    from mercmac.compiler.ast_builder import RULES
    from mercmac.compiler.parse import read

    report = Report("t.mcm")
    parsed = parse_partial(text, report)
    tree = None if parsed.tree is None else build(parsed.tree)
    return read(text, RULES), tree, parsed.failed or bool(report.items)


def compiled(text: str) -> tuple:
    """Every diagnostic `check` gives and the MD lines `build` gives."""
    result = compile_source(Source("t.mcm", text))
    md = None if result.program is None else result.program.md_lines()
    return _diagnostics(result.report), md


def _check_readings(text: str) -> None:
    fast, slow, reported = both_readings(text)
    assert (fast is None) == reported  # declined exactly where lark's reading reports
    if fast is not None:
        assert repr(fast) == repr(slow)  # repr names the node types: == on tuples does not
        with mock.patch.object(ast_builder, "read", lambda text, rules: None):
            by_lark = compiled(text)  # the compiler as it was: lark's reading of every file
        assert compiled(text) == by_lark


@pytest.mark.parametrize("name", sorted(EXAMPLE_TEXTS) + sorted(HOSTILE))
def test_both_readings_agree_on_the_examples_and_hostile_texts(name):
    text = EXAMPLE_TEXTS.get(name, HOSTILE.get(name))
    _check_readings(text)


def test_clean_examples_are_read_in_one_pass():
    for text in EXAMPLE_TEXTS.values():
        assert both_readings(text)[0] is not None


@pytest.mark.slow
@settings(max_examples=budget(300), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(sorted({**EXAMPLE_TEXTS, **HOSTILE}.items())), st.randoms())
def test_both_readings_agree_on_mutated_texts(case, rng):
    _check_readings(mutate(case[1], rng))


@settings(max_examples=budget(100), deadline=None)
@given(st.lists(st.sampled_from(["MR 1", "call a", "goto a", "when 1 {", "repeat 2 {",
                                 "every 5ms {", "}", ",", "\n", "\r\n", "// c\n", "TP"]),
                max_size=40),
       st.sampled_from(["\n", "\r\n", "\r"]))
def test_both_readings_agree_on_generated_blocks(parts, end):
    body = " ".join(parts) + " }" * max(0, sum(p.endswith("{") for p in parts)
                                       - parts.count("}"))
    _check_readings(f"macro a {{ {body} }}{end}autostart {{ call a }}{end}")
