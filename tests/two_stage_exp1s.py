"""Exp1S shortened to two arms of a family, for tests: ``shorten`` in this process, or in a Ray
worker as its setup hook (``worker_process_setup_hook = "two_stage_exp1s.shorten"``, with this
folder on the worker's PYTHONPATH)."""

import dataclasses

from softbench import continual
from softbench import protocols

STAGES = ("tendon-1", "tendon-2")  # Exp1S on these arms (of whichever family) instead of 1 .. 5.


def shortened() -> protocols.Protocol:
  return dataclasses.replace(protocols.PROTOCOLS[continual.PROTOCOL], robot_names=STAGES)


def shorten() -> None:
  protocols.PROTOCOLS[continual.PROTOCOL] = shortened()
