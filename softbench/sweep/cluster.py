"""The Ray a sweep runs on: a local one with a worker per core, or a cluster it joins.

A cluster is started with Ray's own commands (``ray start --head`` on one machine, ``ray start
--address=HEAD:6379`` on the others; docs/sweep.md). Every node must run the same softbench
source: ``check_nodes`` compares each node's source hash with the driver's before any work.
"""

from collections.abc import Iterator
import contextlib
import os
import socket

import ray
from ray.util import scheduling_strategies

from smpl.files import first_line
from softbench import storage
from softbench import zoo
from softbench.episodes import snapshots as episode_snapshots
from softbench.sweep import guard
from softbench.sweep import tasks

COLLECTION_CORES = 4  # (cores) A babbling collection's simulation threads, at most a node's cores.
CONNECT_TIMEOUT_S = 10.0  # (s) How long a cluster's head may take to answer.
MAX_RETRIES = 3  # Attempts of a task after its worker died (killed, out of memory, node lost).
_PROPAGATED = (storage.HOME_VARIABLE, zoo.VARIABLE)  # Environment the workers get from the driver.
_LOOPBACK = ("localhost", "127.0.0.1", "::1")
_NODE_FACTS = ray.remote(num_cpus=1)(tasks.node_facts)


class ClusterUnavailable(RuntimeError):
  """The sweep's own local Ray did not start (seen when its processes were held up at startup:
  "The current node timed out during startup")."""


@contextlib.contextmanager
def connected(address: str | None) -> Iterator[None]:
  """Within the block, Ray: the caller's if it started one, else the cluster at ``address``, else
  a local Ray with one worker per core; left (a local one: shut down) at the end, Ctrl-C too. A
  local Ray's processes end with this one even when it is killed outright (``guard``)."""
  if ray.is_initialized():
    yield
    return
  local_ray = None
  if address is None:
    before = guard.children(os.getpid())
    # "local": a Ray of its own even where RAY_ADDRESS or a running `ray start` names another.
    try:
      ray.init(address="local", num_cpus=os.cpu_count(), include_dashboard=False)
    except Exception as error:  # Ray raises a bare Exception when its node does not come up.
      ray.shutdown()
      raise ClusterUnavailable(
        f"the local Ray did not start ({first_line(error)}); run the same command again: the "
        "records written so far are kept"
      ) from None
    local_ray = guard.start(guard.children(os.getpid()) - before)  # Ends with this process.
  else:
    _check_answers(address)
    try:
      ray.init(address=address)
    except ConnectionError as error:  # Something answers there, but not a Ray head.
      raise ValueError(
        f"no Ray cluster at {address}: something answers there, but Ray cannot join it"
        f" ({first_line(error)}); start one with ray start --head"
      ) from None
  try:
    yield
  finally:
    ray.shutdown()
    guard.stop(local_ray)


def _check_answers(address: str) -> None:
  """Refuses an address where no Ray head listens (``ray.init`` would wait for one forever).

  Raises:
    ValueError: ``address`` is not ``HOST:PORT``, or nothing answers there (one line).
  """
  host, _, port = address.rpartition(":")
  if not host or not port.isdigit():
    raise ValueError(f"a Ray cluster's address is HOST:PORT, got {address!r}")
  if host in _LOOPBACK:  # ray.init connects to this machine's own address instead.
    host = ray.util.get_node_ip_address()
  try:
    socket.create_connection((host, int(port)), CONNECT_TIMEOUT_S).close()
  except OSError as error:
    raise ValueError(
      f"no Ray cluster answers at {address} ({error.strerror or error}); start one with "
      f"ray start --head"
    ) from None


def runtime_env() -> dict:
  """Every task's runtime environment: the driver's data home and zoo, where it names them
  (otherwise a worker uses its own user's default data home)."""
  return {"env_vars": {name: os.environ[name] for name in _PROPAGATED if os.environ.get(name)}}


def _cores_by_node() -> dict[str, int]:
  """Each live node's id and cores."""
  return {
    node["NodeID"]: int(node["Resources"].get("CPU", 0))
    for node in ray.nodes()
    if node["Alive"] and node["Resources"].get("CPU", 0) >= 1
  }


def cores() -> int:
  """The cluster's cores (every node's), for the progress display."""
  return sum(_cores_by_node().values())


def collection_cores() -> int:
  """The cores a babbling collection task asks for: ``COLLECTION_CORES``, at most a node's."""
  return min(COLLECTION_CORES, max(_cores_by_node().values(), default=1))


def check_nodes() -> str:
  """The device the workers train on, once every node is known to run this source.

  Raises:
    ValueError: a node runs other softbench or smpl source than the driver (one line).
  """
  nodes = list(_cores_by_node())
  facts = ray.get(
    [
      _NODE_FACTS.options(
        runtime_env=runtime_env(),
        scheduling_strategy=scheduling_strategies.NodeAffinitySchedulingStrategy(node, soft=False),
      ).remote()
      for node in nodes
    ]
  )
  here = episode_snapshots.source_sha256()
  for node, (source, _) in zip(nodes, facts):
    if source != here:
      raise ValueError(
        f"Ray node {node} runs other softbench source than this machine (sha256 {source[:12]} "
        f"against {here[:12]}); install the same commit on every node"
      )
  return ", ".join(sorted({device for _, device in facts}))
