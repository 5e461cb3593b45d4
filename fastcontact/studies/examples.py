"""The shipped example scenes (``fastcontact/scenes/*.toml``, canned studies) and the lookup
of embedded default tables by name."""
from __future__ import annotations

from pathlib import Path

from .schema import did_you_mean

__all__ = ["list_example_scenes", "example_scene_path", "default_table_path", "SCENES_DIR"]

_PACKAGE = Path(__file__).resolve().parent.parent
SCENES_DIR = _PACKAGE / "scenes"


def list_example_scenes() -> list:
    """Names of the example scenes shipped in ``fastcontact/scenes``."""
    return sorted(p.stem for p in SCENES_DIR.glob("*.toml"))


def example_scene_path(name) -> Path:
    """Path of the shipped example scene ``name`` (with or without ``.toml``).

    Raises
    ------
    FileNotFoundError
        With the closest shipped name.
    """
    p = SCENES_DIR / (name if str(name).endswith(".toml") else f"{name}.toml")
    if not p.is_file():
        raise FileNotFoundError(f"scene {name!r} is neither a file nor a shipped example scene"
                                + did_you_mean(name, list_example_scenes()))
    return p


def default_table_path(name) -> Path:
    """Path of an embedded default table (``asphalt_072mm``, ``pmma_34um`` ...).

    Looks in the package data ``fastcontact/data/`` first, then the source checkout's
    ``tables/`` folder. ``name`` may omit the ``.parquet`` suffix.

    Raises
    ------
    FileNotFoundError
        Listing the available names.
    """
    name = str(name)
    if not name.endswith(".parquet"):
        name += ".parquet"
    if "/" in name or "\\" in name or name.startswith("."):
        raise FileNotFoundError(f"table {name!r} is not a default table name")
    dirs = [_PACKAGE / "data", _PACKAGE.parent / "tables"]
    for d in dirs:
        p = d / name
        if p.is_file():
            return p
    avail = sorted({p.name for d in dirs if d.is_dir() for p in d.glob("*.parquet")})
    raise FileNotFoundError(f"table {name!r} is neither a file nor an embedded default table "
                            f"(available: {', '.join(avail) or 'none'})")
