"""The shipped levels: where they are, their names, and a one-line summary of each, read from the level
files' ``name`` and ``description`` keys without loading the levels (nor importing the engine), so that
``marbellous levels`` answers at once."""
import pathlib

try:
    import tomllib
except ImportError:  # Python < 3.11
    import tomli as tomllib

#: Where the shipped levels live.
LEVEL_DIR = pathlib.Path(__file__).resolve().parent.parent / "levels"
#: The level ``marbellous demo`` and ``marbellous play`` use when none is named.
DEFAULT_LEVEL = "course"


def level_names():
    """Names of the shipped levels (file stems in :data:`LEVEL_DIR`), sorted."""
    return sorted(p.stem for p in LEVEL_DIR.glob("*.toml"))


def level_summary(name):
    """``(title, description)`` of the shipped level ``name``: its ``name`` and ``description`` keys (the
    file stem and an empty string where they are missing).  Reads only the TOML file; ``load_level``
    validates the whole level."""
    if name not in level_names():
        raise ValueError(f"level must be one of {', '.join(level_names())}, got {name!r}")
    data = tomllib.loads((LEVEL_DIR / f"{name}.toml").read_text(encoding="utf-8"))
    title, description = data.get("name", name), data.get("description", "")
    return (title if isinstance(title, str) else name), (description if isinstance(description, str) else "")
