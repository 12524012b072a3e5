"""docs/rules.md: what `mercmac explain` says of every rule, on one page, so that a rule's
code can link to its long story: the editor's diagnostic code (LSP `codeDescription`) and
SARIF's `helpUri` point at the rule's heading there.

`python -m mercmac.render.rules_page > docs/rules.md` writes it; a test keeps it current.
"""
from __future__ import annotations

from mercmac import diagnostics, hazards
from mercmac.diagnostics import Rule

# Where docs/rules.md is published: the project's repository (editors/vscode/package.json).
PAGE = "https://github.com/mercmac/mercmac/blob/main/docs/rules.md"


def url(rule: Rule) -> str:
    """The address of the rule's heading on the published page."""
    return f"{PAGE}#{anchor(rule)}"


def anchor(rule: Rule) -> str:
    """The anchor a Markdown renderer (GitHub, MkDocs) gives the heading '### MM011
    nested-call': lower case, the space a hyphen (a rule name is kebab-case already)."""
    return f"{rule.code.lower()}-{rule.name}"


def markdown() -> str:
    """The page: per kind of rule, each rule's code, name, severity, summary and story."""
    program = tuple(r for r in diagnostics.RULES if r.code.startswith("MM"))
    sections = (("Program rules (MM)", "what `mercmac check` reports in a program", program),
                ("Rig rules (MR)", "what `mercmac check RIG` reports in a rig file",
                 tuple(r for r in diagnostics.RULES if r not in program)),
                ("Runtime hazards (MH)", "what `mercmac sim` reports while it runs",
                 hazards.RULES))
    out = ["# Rules", "",
           "What `mercmac explain CODE` prints for each rule, written by "
           "`python -m mercmac.render.rules_page`. [checks.md](checks.md) says how rules are "
           "chosen and turned off.", ""]
    for title, what, rules in sections:
        out += [f"## {title}", "", f"{what[0].upper()}{what[1:]}.", ""]
        for rule in rules:
            out += [f"### {rule.code} {rule.name}", "",
                    f"*{rule.severity}*: {rule.summary}", "",
                    "```text", *rule.explanation.splitlines(), "```", ""]
    return "\n".join(out)


if __name__ == "__main__":
    import sys

    sys.stdout.write(markdown())
