"""The package's layers import one way: no cycle among softbench's units (its subpackages and
top-level modules), counting every import statement, deferred ones too; and the agent registry,
the records, the leaderboard and the listings of the command line import without torch, the
command line's help and listings run without it, and what seed workers import without
matplotlib."""

import ast
import functools
import pathlib
import subprocess
import sys

import pytest

import softbench

PACKAGE = pathlib.Path(softbench.__file__).parent


def _unit(module: str) -> str | None:
  """The softbench unit (``run``, ``leaderboard``, ...) that ``module`` belongs to, or None."""
  parts = module.split(".")
  if parts[0] != "softbench" or len(parts) < 2:
    return None
  exists = (PACKAGE / parts[1]).is_dir() or (PACKAGE / f"{parts[1]}.py").is_file()
  return parts[1] if exists else None


@functools.cache  # Every rule walks the same files: each is parsed once per process.
def _imported(path: pathlib.Path, module: str, deferred: bool = True) -> frozenset[str]:
  """Every module named by an import statement of ``path`` (module ``module``), relative ones
  resolved; ``from a import b`` names both ``a`` and ``a.b``. Without ``deferred``, only the
  statements run on import (none inside a function)."""
  package = module if path.name == "__init__.py" else module.rpartition(".")[0]
  names = set()
  for node in _nodes(ast.parse(path.read_text(), str(path)), deferred):
    if isinstance(node, ast.Import):
      names.update(alias.name for alias in node.names)
    elif isinstance(node, ast.ImportFrom):
      base = node.module or ""
      if node.level:
        anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
        base = ".".join(anchor + ([node.module] if node.module else []))
      names.add(base)
      names.update(f"{base}.{alias.name}" for alias in node.names)
  return frozenset(names)


def _nodes(tree: ast.AST, deferred: bool):
  """Every node of ``tree``; without ``deferred``, none within a function's body or an
  ``if TYPE_CHECKING:`` block (neither runs on import)."""
  if deferred:
    yield from ast.walk(tree)
    return
  pending = [tree]
  while pending:
    node = pending.pop()
    yield node
    pending.extend(
      child
      for child in ast.iter_child_nodes(node)
      if not isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
      and not _type_checking_only(child)
    )


def _type_checking_only(node: ast.AST) -> bool:
  return isinstance(node, ast.If) and ast.unparse(node.test) in (
    "TYPE_CHECKING",
    "typing.TYPE_CHECKING",
  )


def import_graph() -> dict[str, dict[str, list[str]]]:
  """``graph[unit][other]``: the files of ``unit`` that import ``other``."""
  graph: dict[str, dict[str, list[str]]] = {}
  for path in sorted(PACKAGE.rglob("*.py")):
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
    unit = _unit(module)
    if unit is None:
      continue
    edges = graph.setdefault(unit, {})
    for other in filter(None, map(_unit, _imported(path, module))):
      if other != unit:
        edges.setdefault(other, []).append(str(path.relative_to(PACKAGE.parent)))
  return graph


def find_cycle(graph: dict[str, dict[str, list[str]]]) -> list[str] | None:
  """A cycle of units (first unit repeated at the end), or None."""
  state: dict[str, str] = {}
  stack: list[str] = []

  def visit(unit: str) -> list[str] | None:
    state[unit] = "open"
    stack.append(unit)
    for other in sorted(graph.get(unit, {})):
      if state.get(other) == "open":
        return stack[stack.index(other) :] + [other]
      if other not in state and (cycle := visit(other)):
        return cycle
    state[unit] = "done"
    stack.pop()
    return None

  for unit in sorted(graph):
    if unit not in state and (cycle := visit(unit)):
      return cycle
  return None


def test_softbench_units_import_without_a_cycle():
  graph = import_graph()
  assert {"robots", "suite", "runners", "leaderboard", "records"} <= set(graph)
  cycle = find_cycle(graph)
  assert cycle is None, (
    " -> ".join(f"{unit} ({graph[unit][other][0]})" for unit, other in zip(cycle, cycle[1:]))
    + f" -> {cycle[-1]}"
  )


def test_the_cycle_finder_finds_a_cycle():
  graph = {"a": {"b": ["a.py"]}, "b": {"c": ["b.py"]}, "c": {"a": ["c.py"]}, "d": {}}
  assert find_cycle(graph) == ["a", "b", "c", "a"]
  del graph["c"]["a"]
  assert find_cycle(graph) is None


def _unit_modules(unit: str) -> list[str]:
  """The dotted names of every module of softbench unit ``unit``."""
  base = PACKAGE / unit
  paths = sorted(base.rglob("*.py")) if base.is_dir() else [base.with_suffix(".py")]
  return [
    ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts).removesuffix(".__init__")
    for path in paths
  ]


# (unit, the units it may not import, why)
BOUNDARIES = (
  ("leaderboard", {"runners", "sweep", "learning", "cli"}, "the leaderboard only reads records"),
  ("records", {"runners", "sweep", "learning", "agents", "leaderboard", "cli"}, "records are read"),
  ("learning", {"agents", "runners", "sweep", "cli"}, "training knows no agent or runner"),
  ("agents", {"runners", "sweep", "cli"}, "an agent acts; runners run it"),
  ("continual", {"runners", "sweep", "cli", "leaderboard"}, "strategies learn; runners score"),
  ("runners", {"sweep", "cli"}, "the sweep and the command line call the runners"),
)


@pytest.mark.parametrize(("unit", "forbidden", "why"), BOUNDARIES, ids=[b[0] for b in BOUNDARIES])
def test_each_layer_imports_only_the_layers_below_it(unit, forbidden, why):
  """No file of ``unit`` names a forbidden unit in any import statement (deferred ones too), and
  importing any of its modules loads none."""
  named = {other: files for other, files in import_graph()[unit].items() if other in forbidden}
  assert not named, f"{unit} imports {named} ({why})"
  for module in _unit_modules(unit):
    loaded = {_unit(name) for name in _loaded_with(module)}
    assert not loaded & forbidden, f"importing {module} loads {loaded & forbidden} ({why})"


# What reading results may not load: a simulator or a learning framework. The records and the
# leaderboard know robots and tasks from their registries' catalogues (``robots.catalogue``, the
# task registry), whose engine-bound parts load on first use.
ENGINES = ("mujoco", "dm_control", "torch")
READERS = ("leaderboard", "records")


@pytest.mark.parametrize("unit", READERS)
def test_the_records_and_the_leaderboard_import_no_simulator_and_no_torch(unit):
  for module in _unit_modules(unit):
    engines = sorted({name.split(".")[0] for name in _loaded_with(module)} & set(ENGINES))
    assert not engines, f"importing {module} loads {engines} (reading results needs no engine)"


def test_reading_every_record_loads_no_engine():
  # The walk above sees import statements; this runs them, and reads and ranks the committed
  # records as `softbench leaderboard` does.
  modules = [module for unit in READERS for module in _unit_modules(unit)]
  code = (
    "import importlib, sys\n"
    f"for module in {modules!r}: importlib.import_module(module)\n"
    "from softbench import leaderboard\n"
    f"board = leaderboard.build({str(PACKAGE.parent / 'leaderboard' / 'results')!r})\n"
    "assert board.groups\n"
    f"print(sorted(name for name in {ENGINES!r} if name in sys.modules))"
  )
  result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
  assert result.stdout.strip() == "[]"


def test_the_lazily_loaded_packages_still_give_their_modules_and_names():
  # robots, suite and data load their engine-bound parts on first use: what they gave as
  # attributes when they imported them at once, they give still (in a fresh process, where no
  # other import has loaded the modules before).
  code = (
    "from softbench import data, robots, suite\n"
    "print(robots.tendon.BACKBONES, robots.TendonArm.__name__, suite.tracking.Tracking.__name__,"
    " suite.load.__name__, data.dataset.Dataset.__name__, data.rng.__name__)"
  )
  result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
  assert result.stdout.split() == [
    "('rod',",
    "'cable')",
    "TendonArm",
    "Tracking",
    "load",
    "Dataset",
    "rng",
  ]


# Every module at softbench's top level, and why it is not in a package: a new one says why here.
TOP_LEVEL_MODULES = {
  "__init__": "the package: loads triton before EGL",
  "launcher": "the console entry point: loads MuJoCo before the command line",
  "metrics": "tracking scores, read by episodes, runners, records and the leaderboard alike",
  "plots": "matplotlib figures of episodes and results, for runners and the leaderboard",
  "profiles": "data and epoch budgets, read by every layer",
  "registries": "the naming rule of every registry: agents, tasks, strategies, streams",
  "progress": "progress bars of long work, in every layer",
  "storage": "the data home, atomic writes and hashes, under every layer",
  "terminal": "tables, JSON and one-line warnings on the terminal, for every command",
}


def test_the_top_level_holds_packages_and_a_few_modules_that_say_why():
  modules = {path.stem for path in PACKAGE.glob("*.py")}
  assert modules == set(TOP_LEVEL_MODULES), sorted(modules ^ set(TOP_LEVEL_MODULES))


# The physics side and the environments: tests/test_envs.py.
@pytest.mark.parametrize(
  "modules",
  [
    "softbench.agents, softbench.agents.hyperparameters",
    "softbench.records, softbench.records.exp1s, softbench.records.provenance",
    "softbench.leaderboard, softbench.leaderboard.html_page, softbench.leaderboard.overview",
    "softbench.cli.listings, softbench.terminal",
    "softbench.continual.strategies, softbench.continual.streams, softbench.records.continual",
  ],
)
def test_the_registries_and_the_records_import_without_torch(modules):
  code = f"import sys, {modules}; print('torch' in sys.modules)"
  result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
  assert result.stdout.strip() == "False"


# Commands that read what is registered or recorded, and the help of every command (of those
# that train too). One child for them all: each is a fresh start only for torch's sake.
TORCHLESS_COMMANDS = (
  ["--help"],
  ["--version"],
  ["robots", "tendon-3"],
  ["tasks", "--json"],
  ["agents"],
  ["streams", "--json"],
  ["leaderboard", "--grid", "agents"],
  ["models"],
  ["run", "--help"],
  ["sweep", "--help"],
  ["zoo", "list", "--zoo", str(PACKAGE.parent / "zoo")],  # The tests turn the zoo off.
)


def test_the_help_and_the_listings_of_the_command_line_load_no_torch():
  code = (
    "import sys\n"
    "from softbench import cli\n"
    f"codes = [cli.main(argv) for argv in {list(TORCHLESS_COMMANDS)!r}]\n"
    "print(codes, 'torch' in sys.modules, file=sys.stderr)"
  )
  result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
  codes_and_torch = result.stderr.strip().splitlines()[-1]
  # --help, --version and a command missing its subcommand end as argparse ends them: 0, 0, 2.
  assert codes_and_torch == "[0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0] False"
  assert "usage: softbench" in result.stdout and "tendon-3" in result.stdout


def _module_file(module: str) -> pathlib.Path | None:
  """The source file of softbench module ``module``, or None for another package's."""
  parts = module.split(".")
  if parts[0] != "softbench":
    return None
  base = PACKAGE.parent.joinpath(*parts)
  for path in (base / "__init__.py", base.with_suffix(".py")):
    if path.is_file():
      return path
  return None


def _loaded_with(module: str) -> set[str]:
  """Every module that importing ``module`` loads through softbench's own module-level import
  statements (not those deferred into functions), its packages' ``__init__`` included."""
  loaded, pending = set(), [module]
  while pending:
    name = pending.pop()
    parts = name.split(".")
    for prefix in (".".join(parts[:end]) for end in range(1, len(parts) + 1)):
      if prefix in loaded:
        continue
      loaded.add(prefix)
      path = _module_file(prefix)
      if path is not None:
        pending.extend(_imported(path, prefix, deferred=False))
  return loaded


def test_seed_workers_and_sweep_tasks_load_no_plotting():
  # Each seed worker and Ray task imports these in a fresh process; matplotlib took 0.7 s of it.
  for module in ("softbench.runners.run", "softbench.runners.continual", "softbench.sweep.tasks"):
    loaded = _loaded_with(module)
    assert {"softbench.runners.run", "softbench.agents", "torch"} & loaded, (
      module
    )  # The walk works.
    plotting = sorted(name for name in loaded if name.split(".")[0] == "matplotlib")
    assert not plotting, f"{module} loads {plotting}"
