"""Random streams of softbench: every consumer of randomness draws from its own stream.

A stream is a ``numpy`` generator seeded by ``SeedSequence(seed, spawn_key=(stream, *index))``:
the user's seed, a stream id from the table below, and indices within the stream (an episode
number, say). Streams never overlap, so the training babbling and the held-out babbling of the
task suite are independent for the same seed, and an episode's actions do not depend on how many
episodes there are or on how many threads simulate them. A new consumer takes a new id; an id is
never reused, or cached data would silently change meaning.
"""

import numbers

import numpy as np

BABBLING_STREAM = 0  # Training motor babbling (softbench.data.collect); index: episode.
HELD_OUT_BABBLING_STREAM = 1  # The suite's held-out babbling trajectory (task `babbling`).
RANDOM_AGENT_STREAM = 2  # The `random` agent's actions (softbench.agents.random_actions).
TARGET_STREAM_EPISODES = 3  # Which stretch of targets an interaction episode follows, and its
# random start (softbench.envs.streams); index: episode.


MAX_SEED = 2**32 - 1  # The largest seed every consumer takes (numpy's RandomState, MuJoCo).


def check_seed(seed: int) -> None:
  """The one seed rule of softbench: an integer from 0 to ``MAX_SEED``; a one-line ValueError
  otherwise (a bool, a float, a string, a negative or too large number)."""
  if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or not 0 <= seed <= MAX_SEED:
    shown = repr(seed) if len(repr(seed)) <= 40 else f"{repr(seed)[:40]}..."
    raise ValueError(f"seed must be an integer from 0 to {MAX_SEED}, got {shown}")


def rng(seed: int, stream: int, *index: int) -> np.random.Generator:
  """The generator of ``stream`` at ``index`` for the user's ``seed``.

  Raises:
    ValueError: a negative or non-integer seed.
  """
  check_seed(seed)
  return np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(stream, *index)))
