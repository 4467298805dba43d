"""The workers' bar states (``progress.relay_to``), sent to a sweep's driver through a Ray actor.

A worker's ``put`` does not wait for the actor: a task waiting in ``ray.get`` lends its core back to
Ray, which starts another task on it (three tasks on two cores, seen with a Ray queue's ``put``).
A task waits once, at its end (``flush``), so that the driver has its bars' last states when it
has the task's result.
"""

import contextlib

import ray


@ray.remote(num_cpus=0)
class _Mailbox:
  """The states sent since the driver last took them, in the order they came."""

  def __init__(self) -> None:
    self._states = []

  def put(self, state: tuple) -> None:
    self._states.append(state)

  def take(self) -> list[tuple]:
    states, self._states = self._states, []
    return states


class Relay:
  """Made by the driver and given to every task: the workers ``put``, the driver ``take``s."""

  def __init__(self) -> None:
    self._mailbox = _Mailbox.remote()
    self._last = None  # This process's last put, not yet waited for.

  def put(self, state: tuple) -> None:
    """Sends a bar's ``(process id, description, completed, total)``, the process named by its
    node too (process ids of two nodes may be equal)."""
    worker = (ray.get_runtime_context().get_node_id(), state[0])
    self._last = self._mailbox.put.remote((worker, *state[1:]))  # Not waited for (see above).

  def flush(self) -> None:
    """Waits until the actor holds every state this process put (an actor runs one caller's
    calls in the order they were made)."""
    if self._last is not None:
      ray.get(self._last)
      self._last = None

  def take(self) -> list[tuple]:
    """The states sent since the last ``take``."""
    return ray.get(self._mailbox.take.remote())

  def close(self) -> None:
    """Ends the actor; quietly where Ray itself is gone (the error that ended the sweep says so)."""
    with contextlib.suppress(ray.exceptions.RayError):
      ray.kill(self._mailbox)
