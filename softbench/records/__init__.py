"""Result records: their JSON Schema, their integrity hash, and checked writing and reading.

The package owns every record format and imports no torch and no MuJoCo: run records in
``records.run``, Exp1S records in ``records.exp1s``, continual ones in ``records.continual``, the
fields all share in ``records.fields``, provenance in ``records.provenance``. Runners write
through ``write``; the leaderboard reads through ``read``.

A record is one ``softbench run`` (format ``softbench-result``, version 2): provenance, settings
and per-seed errors; or one ``softbench run --protocol exp1s`` (format
``softbench-exp1s-result``, version 2, schema and checks in ``records.exp1s``); or one
``softbench run --protocol continual`` (format ``softbench-continual-result``, version 1,
``records.continual``). Reading and
writing dispatch on ``format``. ``write`` seals a record with ``sha256``, the hash of the
canonical JSON of everything else in it, and ``read`` refuses a file that is not valid JSON, does
not match its kind's schema (``records.run.schema()``, ``records.exp1s.schema()``, JSON Schema draft
2020-12), holds a non-finite number, no longer matches its hash (a hand-edited number), or
contradicts itself (seed count, module counts, the mean over modules). Every refusal is one line
that names the file.

Fields other than the known ones are allowed only as sections (JSON objects), which other
commands add to their records (a fault, an adaptive schedule); the hash covers them too.
Version 1 records (before the hash) are refused: they cannot be checked.
"""

from collections.abc import Callable
import copy
import dataclasses
import errno
import hashlib
import json
import math
import os
import pathlib
import stat

import jsonschema
from jsonschema import exceptions as schema_exceptions

from softbench import storage
from softbench.records import continual as continual_records
from softbench.records import exp1s as exp1s_records
from softbench.records import fields as record_fields
from softbench.records import run as run_records
from softbench.records.fields import METRICS  # noqa: F401  (records.METRICS)
from softbench.records.run import ADAPTIVE_SECTION  # noqa: F401  (records.ADAPTIVE_SECTION)
from softbench.records.run import FORMAT
from softbench.records.run import VERSION
from softbench.records.run import schema

DEFAULT_FOLDER = pathlib.Path("leaderboard/results")  # The committed leaderboard's records
# (a checkout's): what softbench leaderboard, sweep and zoo read by default.
USER_FOLDER_NAME = "results"  # In the data home: where softbench run writes by default.
INTEGRITY_FIELD = record_fields.INTEGRITY_FIELD
MAX_SAME_NAME = 1000  # Records of one setting and second that ``write_new`` names apart.
_MAX_MESSAGE_CHARS = 160  # Of a schema error's message, so that a refusal stays one line.


def user_folder() -> pathlib.Path:
  """Where ``softbench run`` and ``retrain`` write records by default: ``results`` in the data
  home, the user's own runs, apart from the committed leaderboard (``DEFAULT_FOLDER``), so that
  a run changes nothing in a checkout."""
  return storage.softbench_home() / USER_FOLDER_NAME


class RecordError(ValueError):
  """A result record that cannot be used; the message names the file."""


@dataclasses.dataclass(frozen=True)
class Kind:
  """One kind of record: the version this softbench reads, its schema and its own checks."""

  format: str
  version: int
  schema: Callable[[], dict]
  check: Callable[[dict, record_fields.Refuse], None]


def kinds() -> dict[str, Kind]:
  """Every kind of record, by format."""
  return {
    FORMAT: Kind(FORMAT, VERSION, schema, run_records.check),
    exp1s_records.FORMAT: Kind(
      exp1s_records.FORMAT, exp1s_records.VERSION, exp1s_records.schema, exp1s_records.check
    ),
    continual_records.FORMAT: Kind(
      continual_records.FORMAT,
      continual_records.VERSION,
      continual_records.schema,
      continual_records.check,
    ),
  }


def sections(record: dict) -> tuple[str, ...]:
  """The names of a checked record's extra sections (fields its schema does not name), sorted."""
  return tuple(sorted(set(record) - set(kinds()[record["format"]].schema()["properties"])))


def content_sha256(record: dict) -> str:
  """The sha256 of the canonical JSON (sorted keys, no spaces) of the record without its hash."""
  content = {name: value for name, value in record.items() if name != INTEGRITY_FIELD}
  canonical = json.dumps(
    content, sort_keys=True, separators=(",", ":"), ensure_ascii=False, allow_nan=False
  )
  return hashlib.sha256(canonical.encode("utf-8")).hexdigest()


def seal(record: dict) -> dict:
  """A deep copy of ``record`` with its integrity hash, checked.

  Raises:
    RecordError: the record does not match the schema or contradicts itself (one line).
  """
  sealed = copy.deepcopy({name: value for name, value in record.items() if name != INTEGRITY_FIELD})
  check_finite(sealed, "record")
  sealed[INTEGRITY_FIELD] = content_sha256(sealed)
  validate(sealed, "record")
  return sealed


def dumps(record: dict) -> str:
  """The file content of a record: indented JSON with sorted keys."""
  return json.dumps(record, indent=2, sort_keys=True, allow_nan=False) + "\n"


def write(record: dict, path: pathlib.Path) -> dict:
  """Seals ``record`` and writes it to ``path`` atomically; returns the sealed record."""
  sealed = seal(record)
  storage.write_atomically(path, dumps(sealed))
  return sealed


def write_new(record: dict, path: pathlib.Path) -> pathlib.Path:
  """Seals ``record`` and writes it to ``path`` or, where a file has that name (a run of the same
  setting that finished in the same second), to the first free ``STEM-2.json``, ``STEM-3.json``,
  ...: never over a file, even one that another process writes at the same time
  (``storage.write_new``). Returns the path written.

  Raises:
    FileExistsError: ``MAX_SAME_NAME`` names are taken.
  """
  content = dumps(seal(record))
  for number in range(1, MAX_SAME_NAME + 1):
    candidate = path if number == 1 else path.with_name(f"{path.stem}-{number}{path.suffix}")
    if storage.write_new(candidate, content):
      return candidate
  raise FileExistsError(
    errno.EEXIST, f"{MAX_SAME_NAME} records of this name exist; none written", str(path)
  )


def read(path: pathlib.Path) -> dict:
  """The checked record in ``path``.

  Raises:
    RecordError: the file is not valid JSON or not a valid, untouched record, a broken link, or
      not a regular file (a FIFO, a device; one line).
    FileNotFoundError: no such file.
  """
  path = pathlib.Path(path)
  try:
    mode = os.stat(path).st_mode
    if not stat.S_ISREG(mode):  # A FIFO would be waited on forever.
      raise RecordError(f"{path}: {storage.file_kind(mode)}, not a regular file")
    record = json.loads(path.read_text(encoding="utf-8"))
    validate(record, str(path))
  except FileNotFoundError:
    if path.is_symlink():
      raise RecordError(
        f"{path}: a broken link (to {os.readlink(path)}, which does not exist)"
      ) from None
    raise
  except OSError as error:
    raise RecordError(f"{path}: cannot be read ({error.strerror})") from None
  except UnicodeDecodeError as error:
    raise RecordError(f"{path}: not UTF-8 text ({error.reason})") from None
  except json.JSONDecodeError as error:
    raise RecordError(
      f"{path}: not valid JSON ({error.msg} at line {error.lineno}, column {error.colno})"
    ) from None
  except RecursionError:
    raise RecordError(f"{path}: not a result record (nested too deeply)") from None
  except RecordError:
    raise
  except ValueError as error:  # An integer beyond Python's digit limit, ...
    message = _shortened(str(error).split(";")[0])
    raise RecordError(f"{path}: not a usable record ({message})") from None
  return record


def read_folder(folder: pathlib.Path) -> list[tuple[pathlib.Path, dict]]:
  """Every record (``*.json``) in ``folder``, checked, sorted by file name; none if the folder
  does not exist.

  Raises:
    RecordError: a file is not a valid, untouched record, or ``folder`` is a file or cannot be
      read (one line).
  """
  folder = pathlib.Path(folder)
  try:  # Not pathlib's glob, which takes an unreadable folder for an empty one.
    with os.scandir(folder) as entries:
      names = sorted(entry.name for entry in entries if entry.name.endswith(".json"))
  except FileNotFoundError:
    return []
  except NotADirectoryError:
    raise RecordError(f"{folder}: not a folder of result records") from None
  except OSError as error:
    raise RecordError(
      f"{folder}: the folder of result records cannot be read ({error.strerror})"
    ) from None
  return [(folder / name, read(folder / name)) for name in names]


def validate(record: object, source: str) -> None:
  """Checks a record: format and version, finite numbers, schema, hash, consistency.

  Raises:
    RecordError: the first problem found, one line starting with ``source``.
  """
  if not isinstance(record, dict):
    raise RecordError(f"{source}: not a result record (a JSON object is expected)")
  known = kinds()
  found = record.get("format")
  kind = known.get(found) if isinstance(found, str) else None
  if kind is None:
    raise RecordError(
      f"{source}: not a result record (format {_shortened(repr(found))}, "
      f"expected one of {', '.join(map(repr, known))})"
    )
  version = record.get("version")
  if version != kind.version:
    why = (
      "it has no integrity hash, so it cannot be checked; run it again"
      if isinstance(version, int) and version < kind.version
      else f"this softbench reads version {kind.version}"
    )
    raise RecordError(f"{source}: record version {_shortened(repr(version))} is not read: {why}")
  check_finite(record, source)
  error = schema_exceptions.best_match(
    jsonschema.Draft202012Validator(kind.schema()).iter_errors(record)
  )
  if error is not None:
    raise RecordError(f"{source}: {_describe(error)}")
  if record[INTEGRITY_FIELD] != content_sha256(record):
    raise RecordError(
      f"{source}: content does not match its {INTEGRITY_FIELD} (edited after "
      f"softbench run wrote it?); records must not be edited by hand"
    )

  def refuse(message: str) -> None:
    raise RecordError(f"{source}: {message}")

  kind.check(record, refuse)


def _where(path) -> str:
  where = ""
  for part in path:
    where += f"[{part}]" if isinstance(part, int) else (f".{part}" if where else str(part))
  return where or "record"


def _shortened(message: str) -> str:
  """``message`` in at most ``_MAX_MESSAGE_CHARS`` characters: its middle (a long value) cut,
  so that the reason at its end stays."""
  if len(message) <= _MAX_MESSAGE_CHARS:
    return message
  half = (_MAX_MESSAGE_CHARS - 3) // 2
  return message[:half] + "..." + message[-half:]


def _describe(error: schema_exceptions.ValidationError) -> str:
  where = _where(error.absolute_path)
  extra = error.validator == "additionalProperties" or (
    list(error.schema_path)[-2:] == ["additionalProperties", "type"]
    and error.validator_value == "object"
  )  # An extra field that is not a section.
  if extra:
    return _shortened(
      f"{where}: unknown field (extra fields must be sections, JSON objects): {error.message}"
    )
  return f"{where}: {_shortened(error.message)}"


def check_finite(value: object, source: str, path: tuple = ()) -> None:
  """Raises a one-line RecordError naming ``source`` and the place of the first non-finite
  number in ``value`` (nested dicts and lists)."""
  if isinstance(value, float) and not math.isfinite(value):
    raise RecordError(f"{source}: {_where(path)}: {value} is not a finite number")
  if isinstance(value, dict):
    for key, item in value.items():
      check_finite(item, source, path + (key,))
  elif isinstance(value, list):
    for index, item in enumerate(value):
      check_finite(item, source, path + (index,))
