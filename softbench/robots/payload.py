"""A payload: a mass carried at the arm's tip (the ``payload`` field of every robot, in kg).

The payload is a solid sphere of ``DENSITY`` in a body of its own welded to the last segment at the
last module's tip site (``module{N}_tip``), just past the tip on the arm axis; the sphere's geom
carries the mass (MuJoCo derives its inertia, 2/5 m r²), so it adds exactly ``payload`` kg
whatever the rod's discretisation. It does not collide. A payload
of 0 adds nothing: the MJCF, and so every cache key, is that of the robot without the field.
"""

import math
import numbers

import mujoco

BODY = "payload"
DENSITY = 7850.0  # (kg/m³) Steel: a 20 g payload is a sphere of 8.4 mm radius.
MAX_PAYLOAD = 1.0  # (kg) Larger payloads are refused: 75 times tendon-3's 13 g rod.
_RGBA = (0.55, 0.55, 0.6, 1)


def check(value: float) -> None:
  """Raises a one-line ValueError unless ``value`` is a mass in [0, ``MAX_PAYLOAD``] kg."""
  if (
    isinstance(value, bool)
    or not isinstance(value, numbers.Real)
    or not math.isfinite(value)
    or not 0.0 <= value <= MAX_PAYLOAD
  ):
    raise ValueError(f"payload must be a mass from 0 to {MAX_PAYLOAD:g} kg, got {value!r}")


def radius(mass: float) -> float:
  """Radius (m) of the payload sphere of ``mass`` kg."""
  return (3.0 * mass / (4.0 * math.pi * DENSITY)) ** (1.0 / 3.0)


def apply(spec: mujoco.MjSpec, robot) -> None:
  """Welds the payload of ``robot`` (a ``SoftArm``), if any, at the last module's tip site of its
  freshly built ``spec``."""
  mass = robot.payload
  if not mass:
    return
  site = spec.site(f"module{robot.num_modules}_tip")
  size = radius(mass)
  body = site.parent.add_body(name=BODY, pos=site.pos, quat=site.quat)
  body.add_geom(  # Just past the tip, on the arm axis (the site's z-axis).
    name=f"{BODY}_geom",
    type=mujoco.mjtGeom.mjGEOM_SPHERE,
    size=(size, 0, 0),
    pos=(0, 0, size),
    mass=mass,
    rgba=_RGBA,
    contype=0,
    conaffinity=0,
    group=1,
  )
