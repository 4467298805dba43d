"""Changes that tests make in their own process and, as a Ray job's setup hook, in every Ray
worker of a sweep (``test_sweep``): Exp1S shortened to two arms, or agent builds that fail."""

import dataclasses

from softbench import continual
from softbench import protocols
from softbench.sweep import tasks

EXP1S_STAGES = ("tendon-1", "tendon-2")  # Exp1S on these arms (of whichever family), not 1 .. 5.
BROKEN_BUILD = "an agent build broken on purpose"  # The error of ``break_agent_builds``.


def shortened_exp1s() -> protocols.Protocol:
  return dataclasses.replace(protocols.PROTOCOLS[continual.PROTOCOL], robot_names=EXP1S_STAGES)


def shorten_exp1s() -> None:
  protocols.PROTOCOLS[continual.PROTOCOL] = shortened_exp1s()


def _broken_build(*arguments) -> None:
  raise RuntimeError(BROKEN_BUILD)


def break_agent_builds() -> None:
  tasks.BUILDERS["agent"] = _broken_build
