"""Every rule of docs/checks.md, table-driven: snippets and the rule names they must (not) raise."""
from __future__ import annotations

import pytest

from helpers.compiling import compile_text, rules
from mercmac.diagnostics import RULES, Severity

TP17 = ",".join(["TP"] * 17)
TP16 = ",".join(["TP"] * 16)
MANY = "\n".join(f"macro m{i} {{ TP }}" for i in range(33)) + "\n"

# (rule, snippet, target)
FINDS = [
    ("syntax", "[MC01] MR5000 WS100\n", None),
    ("syntax", "[MC01] EMxx\n", None),
    ("syntax", "MR5000\n", None),
    ("syntax", "macro a {\n  TP\n", None),
    ("goto-not-last", "macro a { goto b, TP }\nmacro b { TP }\n", None),
    ("goto-not-last", "autostart { when 1 { goto b, CN 1 } }\nmacro b { TP }\n", None),
    # a goto that ends a loop parses; it is a warning, not `syntax`
    ("goto-ends-loop", "macro a { repeat 3 { MR 5, goto b } }\nmacro b { TP }\n", None),
    ("goto-ends-loop", "macro x { TP }\nautostart { repeat 3 { CN 1, TT, goto x }, CN 2 }\n", None),
    ("ti-moved", "autostart { repeat 3 { when 1 { TI } } }\n", None),
    ("repeat-zero", "macro a { repeat 0 { TP } }\n", None),
    # every 0ms is a busy loop, flagged like a macro that calls itself in the sim
    ("every-zero", "autostart { every 0ms { when 1 { CN 1 } } }\n", None),
    ("every-zero", "const P = 0\nautostart { every P { TP } }\n", None),
    ("syntax", "[MC01] MR 5.5\n", None),
    ("unknown-command", "[MC01] XY5\n", None),
    ("unknown-command", "macro a { FOO 3 }\n", None),
    ("unknown-command", "[MC01] TP?\n", None),
    ("bad-argument", "[MC01] MR\n", None),
    ("bad-argument", "[MC01] EM\n", None),
    ("bad-argument", "[MC01] TP5\n", None),
    ("bad-argument", "target C-999\n", None),
    ("bad-argument", "[MC01] EM xx\n", None),
    ("bad-argument", "[MC01] MR abc\n", None),
    ("argument-range", "[MC01] RP32569\n", None),
    ("argument-range", "[MC01] CN5\n", None),
    ("argument-range", "[MC01] CF0\n", None),
    ("argument-range", "[MC01] WN5\n", None),
    ("argument-range", "[MC01] WF0\n", None),
    ("argument-range", "[MC01] XN7\n", None),
    ("argument-range", "[MC01] XF0\n", None),
    ("argument-range", "[MC01] CP16\n", None),
    ("argument-range", "[MC01] EM32\n", None),
    ("argument-range", "[MC01] EM0\n", None),
    ("argument-range", "[MC00] SC16\n", None),
    ("argument-range", "[MC01] FE4\n", None),
    ("argument-range", "[MC01] JT4\n", None),
    ("argument-range", "[MC01] JN999\n", None),
    ("argument-range", "[MC01] JN500001\n", None),
    ("argument-range", "[MC01] WA65536\n", None),
    ("argument-range", "[MC01] TA7\n", None),
    ("argument-range", "[MC01] TC5\n", None),
    ("argument-range", "[MC01] ZM4\n", None),
    ("argument-range", "[MC01] MA1073741824\n", None),
    ("argument-range", "[MC01] MR-1000000000\n", None),
    # repeat 0 is left out (repeat-zero), 40000 = 2 x 20000 is RP1,RP19999, and
    # 70000 ms is two WAs; a prime count past 32569 and a period past 16 WAs cannot be expressed
    ("argument-range", "macro a { repeat -1 { TP } }\n", None),
    ("argument-range", "macro a { repeat 32573 { TP } }\n", None),
    ("argument-range", "macro a { every 20min { TP } }\n", None),
    ("argument-range", "autostart { when 7 { TP } }\n", None),
    ("argument-range", "const BIG = 99\nmacro a { CN BIG }\n", None),
    ("too-many-commands", f"[MC01] {TP17}\n", None),
    ("too-many-commands", "macro a { repeat 3 { " + ", ".join(["when 1 { TP }"] * 16) + " } }\n", None),
    ("slot-range", "[MC32] TP\n", None),
    ("slot-range", "macro a @40 { TP }\n", None),
    ("slot-range", MANY, None),
    ("duplicate-slot", "[MC01] TP\n[MC01] TT\n", None),
    ("duplicate-slot", "macro a @1 { TP }\n[MC01] TT\n", None),
    ("duplicate-slot", "autostart { TP }\n[MC00] TT\n", None),
    ("duplicate-slot", "autostart { TP }\nautostart { TT }\n", None),
    ("duplicate-name", "macro a { TP }\nmacro a { TT }\n", None),
    ("sc-outside-autostart", "[MC01] SC0\n", None),
    ("sc-outside-autostart", "autostart { when 1 { SC 0 }, TP }\n", None),
    ("not-in-macro", "[MC01] MD5\n", None),
    ("not-in-macro", "[MC01] RT\n", None),
    ("not-in-macro", "[MC01] RM3\n", None),
    ("not-in-macro", "[MC01] RMALL\n", None),
    ("not-in-macro", "macro a { RZ }\n", None),
    ("model-unsupported", "target C-663\n[MC01] DP200\n", None),
    ("model-unsupported", "target C-863\n[MC01] DC200\n", None),
    ("model-unsupported", "[MC01] TE\n", "C-663"),
    ("model-unsupported", "target C-863\n[MC01] DP200\n", "C-663"),
    ("nested-call", "[MC01] EM2,TP\n[MC02] EM3\n[MC03] TP\n", None),
    ("nested-call", "[MC01] EM2,EM3\n[MC02] TP,EM3\n[MC03] TP\n", None),
    ("nested-call", "macro a { call b, TP }\nmacro b { call c }\nmacro c { TP }\n", None),
    ("nested-call", "autostart { every 20ms { when 1 { call a } } }\nmacro a { TP }\n", None),
    ("nested-call", "macro g { goto m }\nmacro m { CP 3 }\nautostart { call g, CN 1 }\n", None),
    ("nested-call", "macro m3 { TP }\nmacro m4 { TT, goto m3 }\nautostart { repeat 2 { call m4 } }\n", None),
    ("undefined-macro", "[MC01] EM5,TP\n", None),
    ("contradictory-condition", "[MC01] XN1,XF1,TP\n", None),
    ("contradictory-condition", "autostart { when 1 and not 1 { TP } }\n", None),
    ("default-argument", "[MC01] WS\n", None),
    ("default-argument", "[MC01] RP\n", None),
    ("default-argument", "[MC01] DI,TP\n", None),
    ("joystick-in-macro", "[MC01] JN20000\n", None),
    ("unreachable-macro", "[MC00] EM1\n[MC01] TP\n[MC02] TT\n", None),
    ("undefined-name", "autostart { call nowhere }\n", None),
    ("undefined-name", "autostart { goto nowhere }\n", None),
    ("undefined-name", "macro a { SV FAST }\n", None),
    ("undefined-name", "autostart { repeat N { TP } }\n", None),
    ("duplicate-name", "const A = 1\nconst A = 2\n", None),
    # a when reads its inputs once per pass of its loop (MS176E §6.4 XN)
    ("slow-poll", "autostart { every 500ms { when 1 { CN 1 } } }\n", None),
    ("slow-poll", "macro p { WA 100 }\nautostart { repeat 3 { MR 9, WS 200, call p, when 2 { CF 1 } } }\n",
     None),
    ("slow-poll", "[MC00] EM1,WA300,RP\n[MC01] XN1,CN1\n", None),
]

# (rule, snippet, target): snippets that must NOT raise the rule.
CLEAN = [
    ("argument-range", "[MC01] RP32568,EM31,CP15,XN6,JN1000,WA65535,MA-1073741823\n", None),
    ("too-many-commands", f"[MC01] {TP16}\n", None),
    ("too-many-commands", "macro a { " + ", ".join(["TP"] * 40) + " }\n", None),
    ("too-many-commands", f"macro a {{ repeat 3 {{ {TP16} }} }}\n", None),
    ("sc-outside-autostart", "[MC00] SC0\n", None),
    ("sc-outside-autostart", "autostart { SC 0, when 1 { TP } }\n", None),
    ("model-unsupported", "[MC01] DP200,DC200\n", None),
    ("model-unsupported", "target C-663\n[MC01] DP200\n", "C-863"),
    ("nested-call", "[MC01] EM2,TP\n[MC02] TP\n", None),
    ("nested-call", "[MC01] TP,EM2\n[MC02] EM3\n[MC03] TP\n", None),
    ("nested-call", "autostart { when 1 { goto a }, TP }\nmacro a { EM 2 }\n", None),
    ("nested-call", "autostart { when 1 { call a, TT }, TP }\nmacro a { MR 5 }\n", None),
    ("nested-call", "autostart { repeat 3 { call a, TT }, TP }\nmacro a { MR 5 }\n", None),
    ("nested-call", "autostart { every 20ms { when 1 { TP, goto a } } }\nmacro a { TP }\n", None),
    ("nested-call", "macro g { goto m }\nmacro m { CP 3 }\nautostart { CN 1, call g }\n", None),
    ("nested-call", "macro r { repeat 3 { MR 10, TT }, CN 2 }\nautostart { call r, TP }\n", None),
    ("syntax", "macro x { TP }\nautostart { repeat 3 { CN 1, TT, goto x }, CN 2 }\n", None),
    ("goto-not-last", "macro x { TP }\nautostart { repeat 3 { CN 1, TT, goto x }, CN 2 }\n", None),
    ("syntax", "macro a { goto b, TP }\nmacro b { TP }\n", None),
    ("duplicate-slot", "macro a { TP }\nmacro a { TT }\n", None),
    ("argument-range", "autostart { repeat 40000 { TP }, every 70000ms { TP }, repeat 0 { TP } }\n", None),
    ("too-many-commands", "autostart { repeat 3 { " + ", ".join(f"MR {i}" for i in range(1, 16))
     + ", TT }, CP 1 }\n", None),
    ("undefined-macro", "autostart { " + " ".join(f"when 1 {{ TP }}, CN {1 + i % 4}," for i in range(40))
     + " TT }\n", None),
    ("undefined-macro", "[MC01] EM2\n[MC02] TP\n", None),
    ("default-argument", "[MC01] WS100,RP5,DI0,DH,TC,FE\n", None),
    ("unreachable-macro", "[MC01] TP\n[MC02] TT\n", None),
    ("contradictory-condition", "[MC01] XN1,XF2,TP\n", None),
    # 250 ms is a quick press; a when block's own waits run only while it is pressed
    ("slow-poll", "autostart { every 250ms { when 1 { CN 1 } } }\n", None),
    ("slow-poll", "autostart { every 20ms { when 1 { MR 9, WS 900, WA 900 } } }\n", None),
    ("slow-poll", "autostart { every 900ms { CN 1, CF 1 } }\n", None),  # no when: nothing read
    ("slow-poll", "[MC00] EM1,WA20,RP,RP\n[MC01] XN1,MR5,WA900\n", None),  # Example 4's way
    ("slow-poll", "[MC00] EM1,WA900,RP0\n[MC01] XN1,CN1\n", None),  # RP0 repeats nothing
]


@pytest.mark.parametrize("rule,text,target", FINDS, ids=lambda v: v if isinstance(v, str) and "\n" not in v else None)
def test_rule_is_found(rule, text, target):
    assert rule in rules(text, target)


@pytest.mark.parametrize("rule,text,target", CLEAN, ids=lambda v: v if isinstance(v, str) and "\n" not in v else None)
def test_rule_is_not_found(rule, text, target):
    assert rule not in rules(text, target)


def test_every_rule_is_tested_and_explained():
    # invalid-suppression is found by `check` (mercmac.suppress), not by the compiler:
    # tested in test_suppression_comments.py
    tested = {rule for rule, _, _ in FINDS} | {"invalid-suppression"}
    # the rig rules (MR) are found by mercmac/rig/checks.py: tests/rig/test_rig_rules.py
    for r in (r for r in RULES if not r.code.startswith("MR")):
        assert r.name in tested, r.name
        assert r.code.startswith("MM") and len(r.explanation) > 100


def test_codes_and_names_are_unique():
    assert len({r.code for r in RULES}) == len({r.name for r in RULES}) == len(RULES)


def test_severities_follow_spec():
    result = compile_text("[MC01] EM2,TP\n[MC02] EM3\n[MC03] TP\n"
                          "macro a { call b, TP }\nmacro b { call c }\nmacro c { TP }\n")
    nested = [d.severity for d in result.report.items if d.rule.name == "nested-call"]
    assert sorted(nested) == [Severity.ERROR, Severity.WARNING]


def test_emxx_says_what_em_takes_and_points_at_xx():
    [d] = compile_text("[MC18] XN4,EM20,EMxx\n[MC20] TP\n").report.items
    assert d.rule.name == "syntax" and "EM takes a macro number 1-31" in d.message
    assert (d.span.line, d.span.column) == (1, 19)


def test_unknown_command_suggests_nearest():
    [d] = compile_text("[MC01] TQ\n").report.items
    assert "did you mean" in d.message


def test_several_syntax_errors_in_one_run():
    text = "[MC01] MR5000 WS100\n[MC02] TP\nmacro a {\n  MR 5 5\n}\n[MC03] TP TT TP\n"
    found = [(d.rule.name, d.span.line) for d in compile_text(text).report.items]
    assert found == [("syntax", 1), ("syntax", 4), ("syntax", 6)]


def test_mmcrun_syntax_is_accepted():
    text = "// Mercury\u2122 Macro File\r\n[MC00] EM+9, em + 10\r\n[MC09] bf,dp200,DI,dd 200\r\n"
    result = compile_text(text + "[MC10] TP\n")
    assert [d.rule.name for d in result.report.items] == ["default-argument"]
    assert result.program.macros[0].line == "EM9,EM10"
    assert result.program.macros[9].line == "BF,DP200,DI,DD200"


def test_cp1252_header_is_read(tmp_path):
    from mercmac.compiler import compile_file

    path = tmp_path / "mmcrun.mcm"
    path.write_bytes("// Mercury\u2122 Macro File\r\n[MC00] EM1\r\n[MC01] TP\r\n".encode("cp1252"))
    result = compile_file(str(path))
    assert not result.report.items and result.program.macros[1].line == "TP"


def test_target_option_overrides_file():
    assert rules("target C-863\n[MC01] DP200\n") == []
    assert rules("target C-863\n[MC01] DP200\n", "C-663") == ["model-unsupported"]


def test_diagnostics_carry_file_line_column():
    [d] = compile_text("\n\n[MC01] TP, CN 9\n").report.items
    assert (d.file, d.span.line, d.span.column) == ("test.mcm", 3, 15)
