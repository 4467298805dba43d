"""Actuator faults: the physics they specify on every registered robot, their parsing, evaluation
under a fault (``softbench run --fault``) and retraining one SMPL column (``softbench retrain``)."""

import json
import re

import mujoco
import numpy as np
import pytest
import torch

from softbench import agents
from softbench import cli
from softbench import profiles
from softbench import robots
from softbench import storage
from softbench import suite
from softbench.agents import adaptation
from softbench.agents import learned
from softbench.learning import checkpoints
from softbench.robots import faults
from softbench.runners import retrain

STEPS_BEFORE = 60  # Physics steps under a random action, so that forces are read in a bent state.


@pytest.fixture(autouse=True)
def shared_home(tmp_path_factory, babbled_home):
  """One data home for the file, holding tendon-2's tiny dataset: the faulty robots' datasets and
  the checkpoints are made once, then reused."""
  babbled_home(tmp_path_factory.getbasetemp() / "faults_home")


def _test_faults(robot: robots.SoftArm) -> tuple[faults.Fault, ...]:
  """A degraded and a punctured actuator in the last module, and a half-gain one in module 1."""
  last = robot.num_modules
  chosen = [faults.Fault(last, 0, 0.3), faults.Fault(last, 1, 0.0)]
  return tuple(chosen + ([faults.Fault(1, 2, 0.5)] if last > 1 else []))


def _bent_state(model: mujoco.MjModel, ctrl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
  data = mujoco.MjData(model)
  data.ctrl[:] = ctrl
  mujoco.mj_step(model, data, STEPS_BEFORE)
  return data.qpos.copy(), data.qvel.copy()


def _actuator_forces(model: mujoco.MjModel, qpos, qvel, ctrl) -> np.ndarray:
  data = mujoco.MjData(model)
  data.qpos[:], data.qvel[:], data.ctrl[:] = qpos, qvel, ctrl
  mujoco.mj_forward(model, data)
  return data.actuator_force.copy()


@pytest.mark.parametrize("name", robots.REGISTERED_ROBOTS)
def test_a_fault_scales_exactly_its_actuator_and_nothing_else(name):
  healthy = robots.make(name)
  faulty = healthy.with_faults(_test_faults(healthy))
  healthy_model, faulty_model = healthy.compile(), faulty.compile()
  rng = np.random.default_rng(0)
  action = rng.uniform(-1, 1, healthy.action_dim)
  indices = {faults.actuator_index(healthy, fault): fault.gain for fault in faulty.faults}
  action_map = healthy.action_map()
  for index in indices:  # Drive every faulty actuator: the side of its action entry that pulls.
    entry, _, _, at_plus_one = action_map[index]
    action[int(entry)] = 0.8 if at_plus_one != 0 else -0.8
  qpos, qvel = _bent_state(healthy_model, healthy.action_to_ctrl(rng.uniform(-1, 1, len(action))))
  ctrl, rest = healthy.action_to_ctrl(action), healthy.action_to_ctrl(np.zeros_like(action))
  # The force the action adds (cable tension; bellows pull from its commanded length change).
  forces = {
    label: _actuator_forces(model, qpos, qvel, ctrl) - _actuator_forces(model, qpos, qvel, rest)
    for label, model in (("healthy", healthy_model), ("faulty", faulty_model))
  }
  for index in range(healthy_model.nu):
    if index in indices:
      assert abs(forces["healthy"][index]) > 1e-3
      np.testing.assert_allclose(
        forces["faulty"][index], indices[index] * forces["healthy"][index], rtol=1e-9, atol=1e-12
      )
    else:
      assert forces["faulty"][index] == forces["healthy"][index]
  raw = {
    label: _actuator_forces(model, qpos, qvel, ctrl)
    for label, model in (("healthy", healthy_model), ("faulty", faulty_model))
  }
  others = [index for index in range(healthy_model.nu) if index not in indices]
  np.testing.assert_array_equal(raw["faulty"][others], raw["healthy"][others])


@pytest.mark.parametrize("name", robots.REGISTERED_ROBOTS)
def test_the_faulty_mjcf_differs_only_in_the_faulty_gains(name):
  healthy = robots.make(name)
  faulty = healthy.with_faults(_test_faults(healthy))
  healthy_xml, faulty_xml = healthy.to_xml(), faulty.to_xml()
  changed = [
    line for line, other in zip(healthy_xml.splitlines(), faulty_xml.splitlines()) if line != other
  ]
  assert len(changed) == len(faulty.faults)
  strip = lambda xml: re.sub(r' gainprm="[^"]*"', "", xml)
  assert strip(healthy_xml) == strip(faulty_xml)


@pytest.mark.parametrize("name", robots.REGISTERED_ROBOTS)
def test_gain_one_gives_an_identical_model(name):
  healthy = robots.make(name)
  whole = healthy.with_faults(
    faults.Fault(f.module, f.actuator, 1.0) for f in _test_faults(healthy)
  )
  assert whole.to_xml() == healthy.to_xml()
  assert whole.without_faults() == healthy


def test_a_punctured_cable_stops_pulling_in_physics():
  """Holding a full +x pull of module 1: the healthy arm bends, with cable xpos cut it stays."""
  healthy = robots.make("tendon-1")
  tips = {}
  for label, robot in (("healthy", healthy), ("cut", healthy.with_faults([faults.parse("1:0:0")]))):
    model = robot.compile()
    data = mujoco.MjData(model)
    data.ctrl[:] = robot.action_to_ctrl(np.array([1.0, 0.0]))
    mujoco.mj_step(model, data, 100)
    tips[label] = data.site_xpos[model.site("module1_tip").id].copy()
  rest_tip = np.array([0.0, 0.0, -robots.make("tendon-1").length])
  assert np.linalg.norm(tips["healthy"] - rest_tip) > 0.01
  np.testing.assert_allclose(tips["cut"], rest_tip, atol=1e-6)


@pytest.mark.parametrize(
  "text,expected",
  [
    ("2:0:0.3", faults.Fault(2, 0, 0.3)),
    (" 1:3:0 ", faults.Fault(1, 3, 0.0)),
    ("3:2:1", faults.Fault(3, 2, 1.0)),
  ],
)
def test_parse(text, expected):
  parsed = faults.parse(text)
  assert parsed == expected and faults.parse(str(parsed)) == parsed
  assert parsed.punctured == (expected.gain == 0)


@pytest.mark.parametrize(
  "robot,text,message",
  [
    ("tendon-3", "2:0", "malformed fault"),
    ("tendon-3", "2:0:0.3:1", "malformed fault"),
    ("tendon-3", "two:0:0.3", "module must be an integer"),
    ("tendon-3", "2:0.5:0.3", "actuator must be an integer"),
    ("tendon-3", "2:0:high", "gain must be a number"),
    ("tendon-3", "2:0:1.5", r"gain must lie in \[0, 1\]"),
    ("tendon-3", "2:0:-0.1", r"gain must lie in \[0, 1\]"),
    ("tendon-3", "2:0:nan", r"gain must lie in \[0, 1\]"),
    ("tendon-3", "0:0:0.5", "module must be an integer from 1"),
    ("tendon-3", "4:0:0.5", "tendon-3 has modules 1 to 3, not 4"),
    ("tendon-3", "2:4:0.5", "module 2 of tendon-3 has actuators 0 to 3, not 4"),
    ("pneumatic-433", "2:3:0.5", "module 2 of pneumatic-433 has actuators 0 to 2, not 3"),
  ],
)
def test_bad_faults_are_one_line_errors(robot, text, message):
  with pytest.raises(ValueError, match=message) as error:
    robots.make(robot).with_faults([faults.parse(text)])
  assert "\n" not in str(error.value)


def test_an_actuator_takes_one_fault():
  with pytest.raises(ValueError, match="more than one fault"):
    robots.make("tendon-2").with_faults([faults.parse("1:0:0.5"), faults.parse("1:0:0.2")])


def test_targets_are_the_healthy_robots():
  healthy = robots.make("tendon-2")
  faulty = healthy.with_faults([faults.parse("2:0:0")])
  for task, options in (("spiral", {"length": 4}), ("reach", {"steps": 2})):
    first = suite.load(healthy, task, seed=3, **options).reset().observation["target"]
    second = suite.load(faulty, task, seed=3, **options).reset().observation["target"]
    np.testing.assert_array_equal(first, second)


@pytest.mark.parametrize(
  "arguments",
  [
    ["run", "--task", "spiral", "--agent", "zero", "--robot", "tendon-2", "--fault", "2:9:0.5"],
    ["run", "--task", "spiral", "--agent", "zero", "--robot", "tendon-2", "--fault", "2-0-0.5"],
    ["retrain", "--robot", "tendon-2", "--fault", "2:0:7"],
    ["retrain", "--robot", "tendon-2", "--fault", "1:0:0.5", "--fault", "2:0:0.5"],
    ["retrain", "--robot", "tendon-2"],
    ["retrain", "--robot", "tendon-2", "--fault", "2:0:0", "--agent", "lstm"],
    ["retrain", "--robot", "tendon-2", "--fault", "2:0:0", "--baseline", "random"],
  ],
)
def test_cli_bad_faults_exit_2_with_one_line(arguments, capsys):
  assert cli.main(arguments + ["--profile", "tiny"]) == cli.EXIT_USAGE
  error = capsys.readouterr().err
  assert error.startswith("softbench: error: ") and error.count("\n") == 1


def test_cli_run_evaluates_under_the_fault(tmp_path, capsys):
  records = {}
  for label, fault in (("healthy", []), ("cut", ["--fault", "2:0:0", "--fault", "2:2:0"])):
    json_path = tmp_path / f"{label}.json"
    assert (
      cli.main(
        [
          "run",
          "--task",
          "circle",
          "--agent",
          "random",
          "--robot",
          "tendon-2",
          "--profile",
          "tiny",
          "--seeds",
          "1",
          "--results",
          str(tmp_path / "results"),
          "--json",
          str(json_path),
          *fault,
        ]
      )
      == 0
    )
    records[label] = json.loads(json_path.read_text())
  assert "under fault 2:0:0, 2:2:0" in capsys.readouterr().out
  assert records["healthy"]["faults"] == []
  assert [f["actuator_name"] for f in records["cut"]["faults"]] == [
    "module2_cable_xpos",
    "module2_cable_xneg",
  ]
  errors = {
    label: record["per_seed"][0]["position_mm"]["per_module"] for label, record in records.items()
  }
  assert errors["healthy"][1] != errors["cut"][1]
  fault_records = (tmp_path / "results").glob("*fault*.json")
  assert sorted(path.name.split("-fault")[1][:5] for path in fault_records) == ["2.0.0"]


def _state(module: torch.nn.Module) -> dict:
  return {name: tensor.clone() for name, tensor in module.state_dict().items()}


def test_retraining_one_column_leaves_the_others_bit_identical():
  """Module 1 of tendon-2 is punctured: column 1 and both forward models retrain; column 2
  (which reads column 1 laterally) stays bit-identical. ``test_cli_retrain_end_to_end`` covers
  a fault in the last module, whose earlier column must stay bit-identical."""
  healthy = robots.make("tendon-2")
  faulty = healthy.with_faults([faults.parse("1:1:0")])
  smpl = agents.make("smpl", healthy, 0, "tiny")
  columns = [_state(column) for column in smpl.inverse.columns]
  retrained = adaptation.retrain_column(smpl, faulty, profiles.get("tiny"))
  assert retrained.trained_now and retrained.column == 1
  assert retrained.retrained_forward_modules == (1, 2)
  equal = lambda a, b: a.keys() == b.keys() and all(torch.equal(a[name], b[name]) for name in a)
  after = [column.state_dict() for column in retrained.agent.inverse.columns]
  assert equal(columns[1], after[1]) and not equal(columns[0], after[0])
  assert adaptation.columns_bit_identical(smpl.inverse, retrained.agent.inverse, skip=1)
  assert not adaptation.columns_bit_identical(smpl.inverse, retrained.agent.inverse, skip=2)
  assert equal(columns[0], smpl.inverse.columns[0].state_dict())  # The healthy agent is intact.
  for healthy_controller, controller in zip(smpl.controllers, retrained.agent.controllers):
    assert not equal(healthy_controller.forward.state_dict(), controller.forward.state_dict())
    assert controller.normalisation is healthy_controller.normalisation
  cached = adaptation.retrain_column(smpl, faulty, profiles.get("tiny"))
  assert not cached.trained_now and cached.wall_time_s == retrained.wall_time_s
  assert equal(_state(retrained.agent.inverse), cached.agent.inverse.state_dict())


def test_the_kept_forward_models_are_bit_identical():
  healthy = robots.make("tendon-2")
  smpl = agents.make("smpl", healthy, 0, "tiny")
  retrained = adaptation.retrain_column(
    smpl, healthy.with_faults([faults.parse("2:0:0.3")]), profiles.get("tiny")
  )
  kept, changed = (controller.forward.state_dict() for controller in retrained.agent.controllers)
  assert all(
    torch.equal(tensor, kept[name])
    for name, tensor in smpl.controllers[0].forward.state_dict().items()
  )
  assert not all(
    torch.equal(tensor, changed[name])
    for name, tensor in smpl.controllers[1].forward.state_dict().items()
  )


def test_cli_retrain_end_to_end(tmp_path, capsys):
  json_path = tmp_path / "record.json"
  assert (
    cli.main(
      [
        "retrain",
        "--robot",
        "tendon-2",
        "--fault",
        "2:0:0.3",
        "--profile",
        "tiny",
        "--seeds",
        "1",
        "--results",
        str(tmp_path / "results"),
        "--json",
        str(json_path),
      ]
    )
    == 0
  )
  out = capsys.readouterr().out
  for row in (
    "before the fault",
    "under the fault",
    "column 2 retrained",
    "lstm, retrained from scratch",
    "bit-identical after retraining: yes",
  ):
    assert row in out
  record = json.loads(json_path.read_text())
  fault = record["fault"]
  assert record["faults"][0]["actuator_name"] == "module2_cable_xpos"
  assert fault["module"] == 2 and fault["retrained_forward_models"] == [2]
  assert set(fault["conditions"]) == {"before", "under", "retrained", "baseline"}
  assert all(seconds > 0 for times in fault["retraining_wall_time_s"].values() for seconds in times)
  assert record["per_seed"] == fault["conditions"]["retrained"]["per_seed"]
  (written,) = (tmp_path / "results").glob("smpl-retrain-tendon-2-fault2.0.0.3-spiral-tiny-*.json")
  assert json.loads(written.read_text()) == record


def test_a_damaged_retrained_column_is_trained_again(assert_one_line_retraining):
  healthy = robots.make("tendon-2")
  faulty = healthy.with_faults([faults.parse("1:0:0.5")])
  smpl = agents.make("smpl", healthy, 0, "tiny")
  first = adaptation.retrain_column(smpl, faulty, profiles.get("tiny"))  # Trained or cached.
  (path,) = (storage.softbench_home() / checkpoints.CHECKPOINT_FOLDER).glob(
    "smpl-tendon-2-fault1.0.0.5-*.pt"
  )
  path.write_bytes(b"hello")
  with pytest.warns(storage.CorruptFileWarning) as caught:
    again = adaptation.retrain_column(smpl, faulty, profiles.get("tiny"))
  assert_one_line_retraining(caught, path)
  assert again.trained_now and again.wall_time_s == adaptation.read_wall_time(path)
  assert _state(first.agent.inverse).keys() == again.agent.inverse.state_dict().keys()
  assert all(
    torch.equal(tensor, again.agent.inverse.state_dict()[name])
    for name, tensor in _state(first.agent.inverse).items()
  )  # Deterministic retraining.
  assert not adaptation.retrain_column(smpl, faulty, profiles.get("tiny")).trained_now


def test_the_baselines_timing_notices_a_damaged_checkpoint_trained_again():
  settings = retrain.settings(robot="tendon-2", faults=("2:0:0.3",), profile="tiny", seeds=1)
  faulty = robots.make("tendon-2").with_faults(settings.run.faults)
  retrain._timed_baseline(settings, faulty, 0, False)  # Trained, or found in the shared home.
  _, seconds, trained_now = retrain._timed_baseline(settings, faulty, 0, False)
  assert not trained_now
  path = learned.checkpoint_path(
    settings.baseline, faulty, 0, settings.run.profile, per_module=False
  )
  path.write_bytes(path.read_bytes()[:500])
  with pytest.warns(storage.CorruptFileWarning):
    _, seconds, trained_now = retrain._timed_baseline(settings, faulty, 0, False)
  assert trained_now and seconds == adaptation.read_wall_time(path) and seconds > 0
