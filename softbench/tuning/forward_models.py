"""The frozen forward models a tuning study trains its inverse models through, trained once.

Forward models do not depend on the inverse model's hyperparameters, so every trial of a study,
and every study on the same robot, view, profile and seed, shares them: they are trained exactly
as a learned agent trains them (``learned.forward_config``) and cached under
``$SOFTBENCH_HOME/tuning/forward`` by a hash of everything their weights depend on.
"""

import dataclasses
import hashlib

from smpl import checkpoint
from smpl import forward_model as smpl_forward
from smpl import training
from softbench import data
from softbench import profiles
from softbench import protocols
from softbench import storage
from softbench.agents import learned
from softbench.robots import base as robot_base

FOLDER = "tuning/forward"


@dataclasses.dataclass(frozen=True)
class ForwardModelConfig:
  """Everything a cached forward model's weights depend on; its hash names the file."""

  robot: str
  robot_xml_sha256: str
  view: str
  samples: int
  data_seed: int
  seed: int
  max_epochs: int
  patience: int
  compile: bool
  training_version: int = learned.TRAINING_VERSION

  @property
  def key(self) -> str:
    text = repr(dataclasses.astuple(self)).encode()
    return (f"{self.robot}-{self.view}-seed{self.seed}-"
            f"{hashlib.sha256(text).hexdigest()[:12]}")


def prepare(robot: robot_base.SoftArm, views: list[data.View], profile: profiles.Profile,
            seed: int, show_progress: bool = False
            ) -> tuple[list[data.SplitWindows], list[smpl_forward.ForwardModel]]:
  """Each view's windows of the profile's babbling dataset and its frozen forward model, from
  the cache or trained now and cached."""
  dataset = data.collect(robot, samples=profile.samples, seed=learned.DATA_SEED,
                         progress=show_progress)
  xml_sha256 = hashlib.sha256(robot.to_xml().encode()).hexdigest()
  config = learned.forward_config(seed, profile)
  windows, forwards = [], []
  for view in views:
    key = ForwardModelConfig(robot.name, xml_sha256, view.name, profile.samples,
                             learned.DATA_SEED, seed, config.max_epochs, config.patience,
                             config.compile)
    path = storage.softbench_home() / FOLDER / f"{key.key}.pt"
    if path.exists():
      split = data.windows(dataset, view)
      model = smpl_forward.ForwardModel(split.train.actuation_size, split.train.pose_size)
      checkpoint.load_checkpoint(path, model, key)
      model.freeze()
    else:
      column = protocols.prepare_column(robot, view, dataset, config, training.default_device())
      split, model = column.windows, column.forward_model
      checkpoint.save_checkpoint(path, model, key)
    windows.append(split)
    forwards.append(model.eval())
  return windows, forwards
