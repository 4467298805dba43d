"""Changes that tests make in their own process and, as a Ray job's setup hook, in every Ray
worker of a sweep (``test_sweep``): Exp1S shortened to two arms, the zero agent's evaluations
failing, or a two-stage continual stream registered."""

import dataclasses

from softbench import robots
from softbench.learning import protocols
from softbench.runners import continual
from softbench.runners import run
from softbench.runners import run_settings

EXP1S_STAGES = ("tendon-1", "tendon-2")  # Exp1S on these arms (of whichever family), not 1 .. 5.
BROKEN = "an evaluation broken on purpose"  # The error of ``break_zero_evaluations``.


def shortened_exp1s() -> protocols.Protocol:
  return dataclasses.replace(protocols.PROTOCOLS[continual.PROTOCOL], robot_names=EXP1S_STAGES)


def shorten_exp1s() -> None:
  protocols.PROTOCOLS[continual.PROTOCOL] = shortened_exp1s()


def break_zero_evaluations() -> None:
  """Every seed of the zero agent raises (``run.fresh_seed``, which a sweep's evaluation calls)."""
  fresh_seed = run.fresh_seed

  def broken_for_zero(settings: run_settings.RunSettings, seed: int, show_progress: bool = False):
    if settings.agent == "zero":
      raise RuntimeError(BROKEN)
    return fresh_seed(settings, seed, show_progress)

  run.fresh_seed = broken_for_zero


PAIR_STAGES = ("tendon-1", "tendon-2")  # The continual test stream ``pair``.


def pair_stream():
  """The stream ``pair``: tendon-1, then tendon-2 (of whichever family)."""
  from softbench.continual import streams

  return streams.Stream(
    "pair",
    "one module, then two",
    lambda family: tuple(
      streams.Configuration(f"{family}-{name[-1]}", robots.make(f"{family}-{name[-1]}"))
      for name in PAIR_STAGES
    ),
  )


def register_pair_stream() -> None:
  from softbench.continual import streams

  if "pair" not in streams.STREAMS:
    streams.register(pair_stream())
