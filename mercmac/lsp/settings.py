"""The editor's settings for mercmac: the `mercmac` section of its workspace configuration.

    "mercmac.target": "C-863" | "C-663" | null     like `check --target`
    "mercmac.select": ["MM011", "nested-call"] | null   like `check --select`
    "mercmac.ignore": ["unreachable-macro"] | null      like `check --ignore`

They override mercmac.toml / `[tool.mercmac]` key by key, as `check`'s options do
(mercmac.compiler.checking). A key that is wrong is said and left out; the others apply.
Keys of the section that are not the server's (the VS Code extension's `path`) are passed over.
"""
from __future__ import annotations

import reprlib

from mercmac import suppress
from mercmac.commands import MODELS
from mercmac.compiler import checking
from mercmac.errors import SettingsError

SECTION = "mercmac"


def options_from(section) -> tuple[checking.Options, list[str]]:
    """The Options of a `mercmac` settings section (None: none given), and what is wrong in it."""
    if section is None:
        return checking.Options(), []
    if not isinstance(section, dict):
        return checking.Options(), [f"the {SECTION} settings are {_kind(section)}, not an object"]
    kept, problems = {}, []
    for key in ("target", "select", "ignore"):
        value = section.get(key)
        if value is None:
            continue
        try:
            kept[key] = _read(key, value)
        except SettingsError as e:
            problems.append(f"{e.message} ({e.hint})" if e.hint else e.message)
    return checking.Options(**kept), problems


def _read(key: str, value):
    """One setting as Options holds it; a SettingsError names the setting."""
    name = f"{SECTION}.{key}"
    if key == "target":
        if not isinstance(value, str) or value.upper() not in MODELS:
            raise SettingsError(f"{name} = {reprlib.repr(value)} is not a model: use "
                                f"{' or '.join(MODELS)} (or null)")
        return value.upper()
    if isinstance(value, str):  # one rule, or several comma-separated, as `--select` takes
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        bad = next((v for v in value if not isinstance(v, str)), value) \
            if isinstance(value, list) else value
        raise SettingsError(f"{name} must be a list of rule codes or names (strings), e.g. "
                            f'["MM011", "undefined-macro"]; found {_kind(bad)}')
    read = suppress.selection if key == "select" else suppress.rule_set
    return read(value, name)


def _kind(value) -> str:
    """'a string', 'a list', ... as JSON names the type of a value."""
    names = {str: "a string", bool: "a boolean", int: "a number", float: "a number",
             list: "a list", dict: "an object"}
    return names.get(type(value), type(value).__name__)
