"""Run profiles: how much data, training and how many seeds a ``softbench run`` spends.

- ``paper``: the paper's budget: 14,000 babbling samples, up to 800 epochs with early stopping,
  5 seeds.
- ``default``: a budget that finishes ``softbench run --task spiral --agent smpl`` on a 2-core
  laptop CPU in about 10 minutes and still gives meaningful numbers.
- ``tiny``: for tests and smoke checks only; its numbers mean nothing.
"""

import dataclasses


@dataclasses.dataclass(frozen=True)
class Profile:
  name: str
  samples: int  # Motor-babbling samples per robot.
  max_epochs: int  # Epoch budget of every model (forward and inverse).
  patience: int  # Epochs without a better validation loss before training stops.
  seeds: int  # Training and evaluation seeds.
  compile: bool  # torch.compile the training step (smpl.fitting.TrainingConfig.compile).
  episode_length: int | None = None  # Control steps per episode (suite.length_options); None:
  # the task's default.

  def training(self) -> dict:
    """What a trained model's weights depend on in this profile, by field name: the one reading of
    a profile by every training config (``softbench.learning``)."""
    return {
      "samples": self.samples,
      "max_epochs": self.max_epochs,
      "patience": self.patience,
      "compile": self.compile,
    }


PROFILES = {
  "paper": Profile("paper", samples=14_000, max_epochs=800, patience=50, seeds=5, compile=True),
  "default": Profile("default", samples=4_000, max_epochs=30, patience=6, seeds=5, compile=False),
  "tiny": Profile(
    "tiny", samples=200, max_epochs=2, patience=2, seeds=2, compile=False, episode_length=4
  ),
}
DEFAULT_PROFILE = "default"
MAX_SEEDS = 1_000  # Seeds of one run at most (200 times the paper's 5), checked before any work:
# a run holds every seed's episode, so a count of 10^20 filled the memory instead of starting.


def get(name: str) -> Profile:
  if name not in PROFILES:
    raise ValueError(f"unknown profile {name!r}; choose one of {', '.join(PROFILES)}")
  return PROFILES[name]
