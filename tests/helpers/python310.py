"""Python 3.10 within a newer Python: no tomllib, so mercmac reads TOML with tomli."""
from __future__ import annotations

import importlib.util
import sys
import types


def without_tomllib(monkeypatch) -> types.ModuleType:
    """Make `import tomllib` fail, as on Python 3.10, and give `import tomli` the real tomli
    where it is installed, else a stand-in module of that name that parses as tomllib does
    (3.11's tomllib is tomli 2); the module that `import tomli` now gives."""
    if importlib.util.find_spec("tomli") is not None:
        import tomli
    else:
        import tomllib

        tomli = types.ModuleType("tomli")
        tomli.loads, tomli.TOMLDecodeError = tomllib.loads, tomllib.TOMLDecodeError
    monkeypatch.setitem(sys.modules, "tomli", tomli)
    monkeypatch.setitem(sys.modules, "tomllib", None)  # `import tomllib` fails, as on 3.10
    return tomli
