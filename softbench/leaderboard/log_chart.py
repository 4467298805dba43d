"""The geometry of a horizontal bar chart on a logarithmic axis, which the page's template draws as
inline SVG: one bar per row from the axis's left end to the row's mean, a whisker over its
interval, and a tick per decade.

A log axis keeps the reference agent's 0.001 mm and the random agent's 100 mm on one chart; a
zero (or negative) mean has no bar and shows its value only.
"""

import dataclasses
import math

from softbench.leaderboard import ranking

WIDTH = 420  # (px) of a chart: three fit beside each other in the page's 1400 px.
LABEL_WIDTH = 90  # (px) left of the bars, for the row's label (an agent's name).
VALUE_WIDTH = 64  # (px) right of the bars, for the mean.
ROW_HEIGHT = 22  # (px) per bar.
BAR_HEIGHT = 14  # (px)
PAD = 6  # (px) above the first bar.
AXIS_HEIGHT = 20  # (px) below the last bar, for the decade ticks.
MAX_TICKS = 7  # Decade ticks at most; more decades get a tick every other decade (or wider).
PLAIN_POWERS = range(-2, 4)  # Decades labelled in full (0.01 .. 1000); others as 1e-4, 1e5.


@dataclasses.dataclass(frozen=True)
class Bar:
  label: str
  title: str  # The tooltip: the label and the full figure.
  middle: float  # (px) y of the bar's centre line.
  top: float  # (px) y of the bar's top edge.
  width: float  # (px) 0 for a mean of 0 or below.
  whisker: tuple[float, float] | None  # (px) x of the interval's ends.
  value: str  # The mean as the pages print it.


@dataclasses.dataclass(frozen=True)
class Chart:
  caption: str
  width: int
  height: int
  left: int  # (px) x of the axis's left end (the bars' start).
  right: int  # (px) x of the axis's right end.
  axis: float  # (px) y of the axis line.
  bar_height: int
  bars: tuple[Bar, ...]
  ticks: tuple[tuple[float, str], ...]  # (x in px, label) per shown decade.


def _decades(values: list[float]) -> tuple[int, int]:
  """The whole decades (powers of ten) that span the positive ``values``."""
  positive = [value for value in values if value > 0]
  if not positive:
    return 0, 1
  low = math.floor(math.log10(min(positive)))
  high = math.ceil(math.log10(max(positive)))
  return low, max(high, low + 1)


def _tick_label(power: int) -> str:
  return f"{10.0**power:g}" if power in PLAIN_POWERS else f"1e{power}"


def chart(rows: list[tuple[str, str, ranking.Estimate]], caption: str) -> Chart:
  """The chart of ``rows`` (label, tooltip label, estimate), in their order."""
  left, right = LABEL_WIDTH, WIDTH - VALUE_WIDTH
  values = [estimate.mean for _, _, estimate in rows]
  values += [bound for _, _, estimate in rows for bound in estimate.interval or ()]
  low, high = _decades(values)

  def x(value: float) -> float:
    if value <= 0:
      return float(left)
    return left + (math.log10(value) - low) / (high - low) * (right - left)

  bars = []
  for index, (label, tooltip, estimate) in enumerate(rows):
    middle = PAD + (index + 0.5) * ROW_HEIGHT
    whisker = None
    if estimate.interval is not None:
      whisker = tuple(round(x(bound), 1) for bound in estimate.interval)
    bars.append(
      Bar(
        label,
        f"{tooltip}: {ranking.cell(estimate)}",
        middle,
        middle - BAR_HEIGHT / 2,
        round(x(estimate.mean) - left, 1),
        whisker,
        ranking.number(estimate.mean),
      )
    )
  step = math.ceil((high - low + 1) / MAX_TICKS)
  ticks = tuple(
    (round(x(10.0**power), 1), _tick_label(power)) for power in range(low, high + 1, step)
  )
  axis = PAD + len(rows) * ROW_HEIGHT
  return Chart(
    caption, WIDTH, int(axis + AXIS_HEIGHT), left, right, axis, BAR_HEIGHT, tuple(bars), ticks
  )
