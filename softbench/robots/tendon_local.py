"""``tendon-local-N``: a modular tendon-driven soft arm whose cables act within their own module.

The backbone, geometry, material, medium, time step and control period of ``tendon-N``, with the
actuation of the paper's simulator (its reference [chen2024novel], a PyElastica Cosserat rod whose
longitudinal muscles act on their own module's elements only): each module's four cables at 90
degrees run from that module's base (the arm's clamp for module 1, the preceding module's tip
plate for the others) through holes near both ends of its own segments to its tip, and through no
other module. A cable's tension thus loads only its module's joints, and leaves equal and opposite
loads at the module's two ends; modules couple only through the shared rod (a distal module rides
on the proximal ones), gravity and the medium's drag. With gravity off, pulling a cable of module
k leaves modules 1 .. k-1 straight, where on ``tendon-N`` it bends them too. Inside its own module
a cable runs 6 mm from the axis, as on ``tendon-N``, so the same Tmax (2.58 N) bends a module by
the same angle relative to its base (measured in both families' model READMEs), and
``tendon-local-1`` has the physics of ``tendon-1``.

Action: two values per module in [-1, 1], as on ``tendon-N``: value a of axis x pulls the +x cable
with tension max(0, a)·Tmax and the -x cable with max(0, -a)·Tmax; likewise for y.
"""

import dataclasses
from typing import ClassVar

from softbench.robots import chain
from softbench.robots import tendon


@dataclasses.dataclass(frozen=True)
class LocalTendonArm(tendon.CableDrivenArm):
  """``tendon-local-N``: the fields of ``tendon.CableDrivenArm``; every cable runs from its own
  module's base to its tip."""

  FAMILY: ClassVar[str] = "tendon-local"

  def cable_route(self, rod: chain.Chain, module: int) -> list[tuple[str, float, float]]:
    """Through the holes of the module's own stretch of the channel, at ``cable_offset``. The
    first of them lies on the body that carries the preceding module's tip plate (a module
    boundary falls at a body's midpoint), so the cable's pull starts there; a cable's stretch
    within one body adds no load."""
    start, tip = rod.geometry.module_start(module), rod.geometry.module_start(module + 1)
    return [
      (f"{prefix}_hole", arc_length, self.cable_offset)
      for prefix, arc_length in rod.channel_holes(self.hole_inset, start=start, end=tip)
    ]
