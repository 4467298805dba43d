"""Train, validation and test splits of a babbling dataset, in contiguous blocks (SPEC 4).

The samples are cut in recording order at 70 % and 80 % of their number, never by shuffling
windows (overlapping windows on both sides of a cut would leak test data into training). With
10 equal episodes that is 7, 1 and 2 episodes. A split may cover parts of several episodes: each
contiguous stretch of one episode inside one split is a ``Piece``, treated as a recording of its
own, so that no window crosses an episode or split boundary.

Time convention as in ``softbench.data.dataset``: a piece of samples [start, stop) holds actions
a_start .. a_{stop-1} and poses x_start .. x_stop, each action with its outcome; the pose where
two pieces of an episode meet ends the one and starts the other.
"""

from collections.abc import Sequence
import dataclasses

import numpy as np

from softbench.data import dataset

SPLITS = ("train", "validation", "test")
FRACTIONS = (0.7, 0.1, 0.2)  # Of the samples, per split, in recording order.


@dataclasses.dataclass(frozen=True)
class Piece:
  """Samples ``[start, stop)`` of episode ``episode``."""

  episode: int
  start: int
  stop: int

  @property
  def samples(self) -> int:
    return self.stop - self.start

  def recording(self, data: dataset.Dataset) -> tuple[np.ndarray, np.ndarray]:
    """Poses (samples + 1, num_modules, 6) and actions (samples, action_dim) of the piece."""
    poses, actions = data.episode(self.episode)
    return poses[self.start : self.stop + 1], actions[self.start : self.stop]


def split_pieces(
  episode_lengths: Sequence[int], fractions: Sequence[float] = FRACTIONS
) -> dict[str, list[Piece]]:
  """The pieces of each split (named as in ``SPLITS``) of episodes of these lengths."""
  if len(fractions) != len(SPLITS) or not np.isclose(sum(fractions), 1.0):
    raise ValueError(f"need {len(SPLITS)} fractions summing to 1, got {tuple(fractions)}")
  lengths = [int(length) for length in episode_lengths]
  episode_starts = np.concatenate([[0], np.cumsum(lengths)])
  cuts = np.rint(np.concatenate([[0.0], np.cumsum(fractions)]) * episode_starts[-1]).astype(int)
  pieces = {}
  for split, split_start, split_stop in zip(SPLITS, cuts[:-1], cuts[1:]):
    pieces[split] = []
    for episode, episode_start in enumerate(episode_starts[:-1]):
      start = max(split_start, episode_start)
      stop = min(split_stop, episode_start + lengths[episode])
      if start < stop:
        pieces[split].append(Piece(episode, int(start - episode_start), int(stop - episode_start)))
  return pieces
