"""What every registry (agents, tasks, continual strategies and streams) asks of a new entry's
name: lowercase words without spaces, not taken."""


def check_new_name(kind: str, name: object, registered) -> None:
  """Raises a one-line ValueError unless ``name`` is well formed and not in ``registered``."""
  if not isinstance(name, str) or not name or name != name.strip().lower() or " " in name:
    raise ValueError(f"{kind} names are lowercase words without spaces, got {name!r}")
  if name in registered:
    raise ValueError(f"{kind} {name!r} is registered already")
