"""Progress bars on an output that is not a terminal (a log file), where rich draws nothing until
the work ends: each bar writes a line of its state at most every ``progress.LOG_INTERVAL_S``; in a
seed worker, hidden bars send their states to the parent."""

import functools
import os
import queue
import re

import pytest
from rich import progress as rich_progress

from smpl import fitting
from softbench import progress
from softbench.sweep import display


def _state_lines(output: str) -> list[str]:
  return [line for line in output.splitlines() if line.endswith(" elapsed")]


def test_a_bar_writes_its_state_to_a_log_at_most_every_interval(capsys, monkeypatch):
  monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.0)  # Every change is due.
  with progress.counting() as bars:
    bar = bars.add_task("seeds", total=5)
    bars.update(bar, completed=1)
    bars.advance(bar)
  lines = _state_lines(capsys.readouterr().out)
  assert len(lines) == 3  # Each change, then the display's end.
  for line, done in zip(lines, (1, 2, 2)):
    assert re.fullmatch(rf"seeds: {done}/5, \d+:\d\d:\d\d elapsed", line), line
  monkeypatch.setattr(progress, "LOG_INTERVAL_S", 3600.0)
  with progress.counting() as bars:
    bar = bars.add_task("seeds", total=5)
    bars.update(bar, completed=1)
    bars.advance(bar)
  (line,) = capsys.readouterr().out.splitlines()  # Only the line that ends the display.
  assert re.fullmatch(r"seeds: 2/5, \d+:\d\d:\d\d elapsed", line), line


def test_a_logged_line_carries_the_extra_columns_unwrapped(capsys, monkeypatch):
  monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.0)
  extra = (rich_progress.TextColumn("{task.fields[failed]} failed,"),)
  label = "a sweep of " + "many " * 20 + "tasks"  # Longer than a log's 80 columns.
  with progress.counting(extra=extra) as bars:
    bars.update(bars.add_task(label, total=4, failed=0), completed=1, failed=2)
  line, last = _state_lines(capsys.readouterr().out)
  assert line == last  # The change, then the display's end.
  assert re.fullmatch(rf"{label}: 1/4, 2 failed, \d+:\d\d:\d\d elapsed", line), line


def test_the_display_ends_with_each_bar_on_one_whole_line(capsys, monkeypatch):
  monkeypatch.setattr(progress, "LOG_INTERVAL_S", 3600.0)  # Nothing due before the end.
  extra = (rich_progress.TextColumn("{task.fields[left]} left,"),)
  labels = ["a sweep of " + "many " * 20 + "tasks", "seeds"]  # The first longer than 80 columns.
  with progress.counting(extra=extra) as bars:
    for total, label in enumerate(labels, start=3):
      bars.update(bars.add_task(label, total=total, left="1:52:10"), completed=2)
  lines = capsys.readouterr().out.splitlines()
  assert len(lines) == 2, lines  # No cropped frame of rich's, no blank line.
  for line, label, total in zip(lines, labels, (3, 4)):
    assert re.fullmatch(rf"{label}: 2/{total}, 1:52:10 left, \d+:\d\d:\d\d elapsed", line), line


def test_a_transient_display_ends_without_a_line(capsys, monkeypatch):
  monkeypatch.setattr(progress, "LOG_INTERVAL_S", 3600.0)
  with progress.counting(transient=True) as bars:
    bars.update(bars.add_task("steps", total=5), completed=5)
  assert capsys.readouterr().out == ""


def test_a_hidden_bar_writes_nothing(capsys, monkeypatch):
  monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.0)
  with progress.counting(show=False) as bars:
    bars.update(bars.add_task("seeds", total=5), completed=1)
  assert capsys.readouterr().out == ""


def _relayed(states: queue.SimpleQueue) -> list[tuple]:
  sent = []
  while not states.empty():
    worker, *state = states.get()
    assert worker == os.getpid()
    sent.append(tuple(state))
  return sent


def test_in_a_seed_worker_a_hidden_bar_sends_its_state_at_most_every_interval(monkeypatch):
  states = queue.SimpleQueue()
  monkeypatch.setattr(progress, "_relay", states)  # As parallel_seeds' workers start.
  monkeypatch.setattr(progress, "RELAY_INTERVAL_S", 3600.0)
  with progress.counting(show=False) as bars:
    bar = bars.add_task("episode", total=3)
    for _ in range(3):
      bars.advance(bar)
  assert _relayed(states) == [("episode", 1, 3), ("episode", 3, 3)]  # The first, then complete.
  report = functools.partial(_report, resumed=False)
  with progress.epochs("forward tendon-1", 800, show=False) as on_epoch_end:
    for epoch in range(5):  # Early stopping after 5 of 800 epochs.
      on_epoch_end(report(epoch))
  assert _relayed(states) == [("forward tendon-1", 1, 800), ("forward tendon-1", 5, 5)]
  monkeypatch.setattr(progress, "_relay", None)  # Not a worker: nothing to show it, no bar.
  with progress.epochs("forward tendon-1", 800, show=False) as on_epoch_end:
    assert on_epoch_end is None


def _clocked(monkeypatch) -> list[float]:
  """Every display of ``progress.counting`` from now on reads the time from the list returned."""
  now, counting = [0.0], progress.counting
  monkeypatch.setattr(
    progress,
    "counting",
    lambda *args, **options: counting(*args, **options, get_time=lambda: now[0]),
  )
  return now


def _report(epoch: int, resumed: bool) -> fitting.EpochReport:
  return fitting.EpochReport(epoch, 1.0, 1.0, 1.0, False, 8.0, resumed)


def test_a_resumed_trainings_relayed_bar_takes_its_pace_from_the_epochs_run_since(
  capsys, monkeypatch
):
  # A forward model resumed at epoch 403 of 800: fit hands on the 403 epochs run before, at
  # once, then runs one every 8 s. Its bar in the sweep's display must not count the 403 as pace.
  states = queue.SimpleQueue()
  monkeypatch.setattr(progress, "_relay", states)
  monkeypatch.setattr(progress, "RELAY_INTERVAL_S", 0.0)  # Every state is sent.
  monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.0)  # Every change is a line.
  now = _clocked(monkeypatch)
  sent = []  # (time, state) as the worker sends them.
  with progress.epochs("forward tendon-3", 800, show=False) as on_epoch_end:
    for epoch in range(406):
      now[0] = 8.0 * max(0, epoch - 402)
      on_epoch_end(_report(epoch, resumed=epoch < 403))
      sent += [(now[0], states.get()) for _ in range(states.qsize())]
  progress.relay_to(None)  # The sweep's own process, which shows them.
  with display.Display(tasks=1, settings=1, show=True) as shown:
    for now[0], state in sent:
      shown.show_workers([state])
  lines = [line for line in _state_lines(capsys.readouterr().out) if "forward" in line]
  # From 404 at 8 s to 406 at 24 s: an epoch in 8 s, so the 394 left take 0:52:32.
  assert re.fullmatch(
    r"forward tendon-3: 406/800, 0:52:32 left, \d+:\d\d:\d\d elapsed", lines[-1]
  ), lines


def test_a_drawn_epoch_bar_shows_the_losses_and_the_time_left_from_the_epochs_run_since(
  capsys, monkeypatch
):
  # softbench run's own process: the same training as above, drawn (here, in a log).
  monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.0)
  now = _clocked(monkeypatch)
  with progress.epochs("forward tendon-3", 800, show=True) as on_epoch_end:
    for epoch in range(406):
      now[0] = 8.0 * max(0, epoch - 402)
      on_epoch_end(_report(epoch, resumed=epoch < 403))
  lines = _state_lines(capsys.readouterr().out)
  last, end = [line for line in lines if "/800" in line][-1], lines[-1]
  losses = "train 1.00e+00, validation 1.00e+00, best 1.00e+00"
  assert last == f"forward tendon-3: 406/800, {losses}, 0:52:32 left, 0:00:24 elapsed"
  assert end == f"forward tendon-3: 406/406, {losses}, 0:00:00 left, 0:00:24 elapsed"
  with pytest.raises(KeyboardInterrupt), progress.epochs("forward tendon-3", 800, True) as bar:
    bar(_report(0, resumed=False))
    raise KeyboardInterrupt  # Interrupted: the bar stays where the training stopped.
  assert _state_lines(capsys.readouterr().out)[-1].startswith("forward tendon-3: 1/800, ")


def test_a_sweeps_time_left_comes_from_its_pace_when_its_tasks_end_minutes_apart(
  capsys, monkeypatch
):
  monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.0)  # Every change is a line.
  now = _clocked(monkeypatch)
  with display.Display(tasks=10, settings=2, show=True) as shown:
    # Tasks 15 minutes apart, then an hour in which none ends (the display updates every minute).
    for done, minutes in ((1, 10), (2, 25), (3, 40), (3, 100)):
      now[0] = 60.0 * minutes
      shown.update(done, 2, 0, 0)
  lines = _state_lines(capsys.readouterr().out)
  assert "-:--:-- left" in lines[0]  # One task ended: no pace yet.
  # Then 2 tasks in 30 minutes: the 7 left take 1:45:00 (rich's default looked 30 s back only).
  assert re.fullmatch(
    r"sweep: tasks: 3/10, 2 running, 0 failed, 0/2 records, 1:45:00 left, "
    r"0:40:00 elapsed",
    lines[2],
  ), lines
  # An hour on, still 2 tasks since the first: 90 minutes for 2, so the 7 left take 5:15:00
  # (rich's own estimate stays at 1:45:00 until a task ends).
  assert re.fullmatch(
    r"sweep: tasks: 3/10, 2 running, 0 failed, 0/2 records, 5:15:00 left, "
    r"1:40:00 elapsed",
    lines[3],
  ), lines


def test_a_sample_bar_updated_a_minute_apart_shows_its_rate_and_time_left(monkeypatch):
  # A SAC training's bar: one update per 1,000-step chunk.
  now = _clocked(monkeypatch)
  with progress.SampleProgress("sac", total=30_000, enabled=False) as bar:
    for chunk in range(1, 4):
      now[0] = 60.0 * chunk
      bar.update(1_000 * chunk)
    (task,) = bar._progress.tasks  # pylint: disable=protected-access
    assert task.speed == pytest.approx(1_000 / 60.0)  # Samples per second, over 2 minutes.
    assert task.time_remaining == pytest.approx(27 * 60.0)


def test_a_hidden_sample_bar_in_a_worker_is_relayed_from_where_it_resumed(capsys, monkeypatch):
  # A SAC training resumed at step 12,000 of 30,000 in a seed worker: its bar is not drawn there,
  # but sent to the parent, whose display shows its pace since the resume and what is left.
  states = queue.SimpleQueue()
  monkeypatch.setattr(progress, "_relay", states)
  monkeypatch.setattr(progress, "RELAY_INTERVAL_S", 0.0)
  monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.0)
  now, sent = _clocked(monkeypatch), []
  with progress.SampleProgress("sac tendon-3 seed 1", 30_000, 12_000, False) as bar:
    for chunk in range(1, 4):
      now[0] = 60.0 * chunk
      bar.update(12_000 + 1_000 * chunk)
      sent += [(now[0], states.get()) for _ in range(states.qsize())]
  assert capsys.readouterr() == ("", "")  # Nothing drawn in the worker.
  assert [state[1:] for _, state in sent] == [
    ("sac tendon-3 seed 1", 13_000 + 1_000 * chunk, 30_000) for chunk in range(3)
  ]
  progress.relay_to(None)
  with display.Display(tasks=1, settings=1, show=True) as shown:
    for now[0], state in sent:
      shown.show_workers([state])
  (*_, line) = [line for line in _state_lines(capsys.readouterr().out) if "sac" in line]
  # 2,000 steps in 2 minutes since the first state: the 15,000 left take 15 minutes.
  assert re.fullmatch(r"sac tendon-3 seed 1: 15000/30000, 0:15:00 left, 0:02:00 elapsed", line)
