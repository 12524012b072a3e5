"""Project settings for `check`: `[tool.mercmac]` in pyproject.toml, or a mercmac.toml,
found upward from the file being checked (SPEC §5).

    [tool.mercmac]                 # in mercmac.toml: the same keys, without the table line
    target = "C-863"               # a default for --target
    select = ["MM011", "undefined-macro"]   # only these rules (codes or names)
    ignore = ["unreachable-macro"]          # never these

In one folder mercmac.toml wins over pyproject.toml; a pyproject.toml without a
`[tool.mercmac]` table is passed over (as ruff does). Command-line options override
these settings key by key.
"""
from __future__ import annotations

import os
import re
from typing import NamedTuple

from mercmac.commands import MODELS
from mercmac.errors import UsageError

KEYS = ("target", "select", "ignore")
# Only a pyproject.toml that has the table is parsed: the others cost one read and no
# TOML import (`check` stays quick to start, benchmarks/check_latency.py).
_TABLE = re.compile(r"^[ \t]*\[[ \t]*tool[ \t]*\.[ \t]*mercmac[ \t]*\]", re.MULTILINE)


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


def _settings_in(folder: str) -> Settings:
    if folder not in _FOUND:
        found = _read_folder(folder)
        if found is None:
            parent = os.path.dirname(folder)
            found = _settings_in(parent) if parent != folder else Settings()
        _FOUND[folder] = found
    return _FOUND[folder]


def _read_folder(folder: str) -> Settings | None:
    """The settings of this folder's mercmac.toml or pyproject.toml; None if it has neither."""
    own = os.path.join(folder, "mercmac.toml")
    if os.path.isfile(own):
        return _parse(own, _load(own, _read(own)))
    project = os.path.join(folder, "pyproject.toml")
    if os.path.isfile(project):
        text = _read(project)
        if _TABLE.search(text):
            table = _load(project, text).get("tool", {}).get("mercmac")
            if isinstance(table, dict):
                return _parse(project, table, "[tool.mercmac] of ")
    return None


def _read(path: str) -> str:
    try:
        with open(path, encoding="utf-8") as f:
            return f.read()
    except (OSError, UnicodeDecodeError) as e:
        raise UsageError(f"cannot read the settings in {path}: {e}") from None


def _load(path: str, text: str) -> dict:
    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise UsageError(f"{path} is not valid TOML: {e}") from None


def _parse(path: str, table: dict, where: str = "") -> Settings:
    """Settings from a table, refusing what `check` would not understand (exit 2)."""
    unknown = sorted(set(table) - set(KEYS))
    if unknown:
        raise UsageError(f"unknown setting{'s' if len(unknown) > 1 else ''} "
                         f"{', '.join(map(repr, unknown))} in {where}{path}",
                         hint=f"mercmac knows {', '.join(KEYS)}")
    target = table.get("target")
    if target is not None and (not isinstance(target, str) or target.upper() not in MODELS):
        raise UsageError(f"target = {target!r} in {where}{path} is not a model: use "
                         f"{' or '.join(MODELS)}")
    return Settings(path, target.upper() if target else None,
                    _rule_list(table, "select", path, where),
                    _rule_list(table, "ignore", path, where))


def _rule_list(table: dict, key: str, path: str, where: str) -> tuple[str, ...] | None:
    value = table.get(key)
    if value is None:
        return None
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise UsageError(f"{key} in {where}{path} must be a list of rule codes or names, "
                         f'e.g. {key} = ["MM011", "undefined-macro"]')
    return tuple(value)
