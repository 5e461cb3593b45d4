"""The shipped example scenes (``fastcontact/scenes/*.toml``, canned studies); the lookup of
embedded default tables by name is :func:`fastcontact.tables.defaults.default_table_path`."""
from __future__ import annotations

from pathlib import Path

from ..tables.defaults import default_table_path
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
