"""The parser's state: the recovery of a parse under way and the named errors'
keys live in an object (mercmac.compiler.parse._Parser), not in module globals that
functions rebind or fill as they go."""
from __future__ import annotations

import ast
from pathlib import Path

import mercmac
from mercmac.compiler import parse
from mercmac.diagnostics import Report

PARSE = Path(mercmac.__file__).parent / "compiler" / "parse.py"


def _module_state(tree: ast.Module) -> list[str]:
    """Module-level names bound to None or to an empty list, dict or set: state that is
    filled in later, not a table."""
    found = []
    for node in tree.body:
        value = node.value if isinstance(node, (ast.Assign, ast.AnnAssign)) else None
        empty = (isinstance(value, ast.Constant) and value.value is None) or (
            isinstance(value, (ast.List, ast.Set)) and not value.elts) or (
            isinstance(value, ast.Dict) and not value.keys)
        if empty:
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            found += [ast.unparse(t) for t in targets]
    return found


def test_the_parse_module_keeps_no_state_in_globals():
    tree = ast.parse(PARSE.read_text(encoding="utf-8"))
    assert [n.names for n in ast.walk(tree) if isinstance(n, ast.Global)] == []
    assert _module_state(tree) == []


def test_a_named_error_is_named_in_every_file_and_reports_only_the_files_errors():
    """The examples of the named errors are parsed amid the first file's parse: none of
    their errors goes to that file's report, and a later file's errors read the same."""
    reports = []
    for _ in range(2):
        report = Report("a.mcm")
        parse.parse_partial("macro a { MR5000 WS100 }\n[MC01] MR5000 WS100\nTP\n", report)
        reports.append([(d.rule.name, d.span.line, d.message) for d in report.items])
    assert [line for _, line, _ in reports[0]] == [1, 2, 3]
    assert reports[1] == reports[0]
