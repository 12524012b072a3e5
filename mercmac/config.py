"""Project settings for `check` and the language server: `[tool.mercmac]` in pyproject.toml,
or a mercmac.toml, found upward from the file being checked (docs/cli.md).

    [tool.mercmac]                 # in mercmac.toml: the same keys, without the table line
    target = "C-863"               # a default for --target
    select = ["MM011", "undefined-macro"]   # only these rules (codes or names)
    ignore = ["unreachable-macro"]          # never these

In one folder mercmac.toml wins over pyproject.toml; a pyproject.toml without a
`[tool.mercmac]` table is passed over (as ruff does). Command-line options override
these settings key by key.

A settings file is UTF-8 TOML, read by mercmac.tomlfile as scenarios and rigs are: a
leading UTF-8 byte-order mark is read past, as ruff and Cargo read one (Windows editors
write it; TOML 1.0 does not forbid it, tomllib alone refuses it). Only a regular file is
read, and at most mercmac.source.MAX_BYTES of it: a FIFO or a link to /dev/zero is named,
not waited on. Whatever is wrong with a settings file stops `check` with a
message naming the file (exit 2).
"""
from __future__ import annotations

import os
import reprlib
from typing import NamedTuple

from mercmac.commands import MODELS
from mercmac.errors import SettingsError
from mercmac.suggest import did_you_mean, suggest

KEYS = ("target", "select", "ignore")
# Only a pyproject.toml that names mercmac is parsed: the others cost one read and no TOML
# import (`check` stays quick to start, benchmarks/check_latency.py). Any mention, not just
# a `[tool.mercmac]` line: the table may be written `tool = {mercmac = {...}}` or
# `[tool]` with `mercmac.select = [...]`, and is the same table in each spelling.
_MENTION = "mercmac"


class Settings(NamedTuple):
    """What a configuration file says; None for a key it leaves out."""

    path: str | None = None
    target: str | None = None
    select: tuple[str, ...] | None = None
    ignore: tuple[str, ...] | None = None


_FOUND: dict[str, Settings] = {}  # folder -> settings, so a tree of files reads each file once


def settings_for(path: str) -> Settings:
    """The settings that apply to the file at `path` ('-' for standard input: the
    working folder's)."""
    folder = os.path.abspath(os.path.dirname(path) if path != "-" else ".")
    return _settings_in(folder)


def forget() -> None:
    """Read the settings files again from now on: the language server runs for hours
    while they are edited."""
    _FOUND.clear()


def _settings_in(folder: str) -> Settings:
    if folder not in _FOUND:
        found = _read_folder(folder)
        if found is None:
            parent = os.path.dirname(folder)
            found = _settings_in(parent) if parent != folder else Settings()
        _FOUND[folder] = found
    return _FOUND[folder]


def _read_folder(folder: str) -> Settings | None:
    """The settings of this folder's mercmac.toml or pyproject.toml; None if it has neither.
    (lexists: whatever stands there under the name is read or named, a FIFO or a broken
    link too, rather than passed over in silence.)"""
    own = os.path.join(folder, "mercmac.toml")
    if os.path.lexists(own):
        table = _load(own, _read(own))
        if isinstance(table.get("tool"), dict) and "mercmac" in table["tool"]:
            raise SettingsError(f"[tool.mercmac] in {own}: a mercmac.toml holds the "
                                "settings at its top level", hint="remove the [tool.mercmac] line")
        return _parse(own, table)
    project = os.path.join(folder, "pyproject.toml")
    if os.path.lexists(project):
        text = _read(project)
        if _MENTION in text:
            return _project_settings(project, _load(project, text))
    return None


def _project_settings(path: str, document: dict) -> Settings | None:
    """The settings in a pyproject.toml's `[tool.mercmac]`, in any TOML spelling; None
    without the table. `[[tool.mercmac]]` (a list of tables) is refused, not guessed at."""
    tool = _table(document.get("tool", {}), "tool", path)
    table = tool.get("mercmac")
    if table is None:
        return None
    if isinstance(table, list):
        raise SettingsError(f"[[tool.mercmac]] in {path} is an array of tables: mercmac "
                            "reads one table", hint="write [tool.mercmac] with single brackets")
    return _parse(path, _table(table, "tool.mercmac", path), "[tool.mercmac] of ")


def _table(value, key: str, path: str) -> dict:
    """VALUE, when it is a TOML table; else the SettingsError that says what it is."""
    if not isinstance(value, dict):
        raise SettingsError(f"{key} in {path} is {_toml_type(value)}, not a table")
    return value


def _toml_type(value) -> str:
    """'a string', 'an array', ... as TOML names the type of a value."""
    names = {str: "a string", bool: "a boolean", int: "an integer", float: "a float",
             list: "an array", dict: "a table"}
    return names.get(type(value), "a date or time")


def _read(path: str) -> str:
    """A settings file's text (mercmac.tomlfile: a regular file, capped, UTF-8)."""
    from mercmac import tomlfile
    from mercmac.outfile import reason

    try:
        return tomlfile.read_text(path)
    except OSError as e:
        raise SettingsError(f"cannot read the settings in {path}: {reason(e)}") from None
    except tomlfile.TomlError as e:
        raise SettingsError(f"cannot read the settings in {path}: {e.why}",
                            hint="save it as UTF-8") from None


def _load(path: str, text: str) -> dict:
    from mercmac import tomlfile

    try:
        return tomlfile.loads(text)
    except tomlfile.TomlError as e:
        at = f" (at line {e.line}, column {e.column})" if e.line else ""
        raise SettingsError(f"{path}: {e.why}{at}") from None


def _parse(path: str, table: dict, where: str = "") -> Settings:
    """Settings from a table, refusing what `check` would not understand (exit 2)."""
    unknown = sorted(set(table) - set(KEYS))
    if unknown:
        keys = ", ".join(reprlib.repr(k) for k in unknown[:5]) + (", ..." if unknown[5:] else "")
        raise SettingsError(f"unknown setting{'s' if len(unknown) > 1 else ''} "
                            f"{keys} in {where}{path}{_meant(unknown[:5])}",
                            hint=f"mercmac knows {', '.join(KEYS)}")
    target = table.get("target")
    if target is not None and (not isinstance(target, str) or target.upper() not in MODELS):
        raise SettingsError(f"target = {reprlib.repr(target)} in {where}{path} is not a model: "
                            f"use {' or '.join(MODELS)}")
    return Settings(path, target.upper() if target else None,
                    _rule_list(table, "select", path, where),
                    _rule_list(table, "ignore", path, where))


def _meant(unknown: list[str]) -> str:
    """What a message of unknown keys ends with where they look misspelt (mercmac.suggest):
    "; did you mean 'select'?", or for several "; did you mean 'select' for 'slect', ...?"."""
    if len(unknown) == 1:
        said = did_you_mean(unknown[0], KEYS)
        return f"; {said}" if said else ""
    meant = [(key, suggest(key, KEYS)) for key in unknown]
    pairs = [f"'{near}' for {reprlib.repr(key)}" for key, near in meant if near]
    return f"; did you mean {', '.join(pairs)}?" if pairs else ""


def _rule_list(table: dict, key: str, path: str, where: str) -> tuple[str, ...] | None:
    value = table.get(key)
    if value is None:
        return None
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise SettingsError(f"{key} in {where}{path} must be a list of rule codes or names, "
                            f'e.g. {key} = ["MM011", "undefined-macro"]')
    return tuple(value)
