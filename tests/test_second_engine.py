"""The second engine: the hand-made forward step, a non-falling forward step in the built-in
physics (nodes/ga_step_sim/tests/webots.rs), is one in MuJoCo too, and a standing Nao stays put
there (tests/mujoco_replay.py; docs/ga_step.md, "Second engine")."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

import mujoco_replay

ROOT = Path(__file__).resolve().parent.parent
HAND_STEP = ROOT / "nodes/ga_step_sim/motions/hand_step.motion"
STEP_MIN_FORWARD = yaml.safe_load((ROOT / "params/nao_step.yaml").read_text())["ga_step"][
    "ros__parameters"]["step_min_forward"]


@pytest.mark.parametrize("control_period", [0.0, 0.02])
def test_the_hand_made_step_is_a_non_falling_forward_step_in_mujoco(control_period: float) -> None:
    # The servos' P-controller every MuJoCo step, and every 20 ms as Webots runs it.
    times, rows = mujoco_replay.read_motion(HAND_STEP)
    o = mujoco_replay.simulate(times, rows, control_period=control_period)
    assert not o.fell, o
    assert o.dx >= STEP_MIN_FORWARD, o
    # A step: each foot lifted at least 1 cm and put down at least 4 cm ahead.
    assert min(o.lift) > 0.01 and min(o.foot_dx) > 0.04, o


def test_a_standing_nao_stays_put_in_mujoco() -> None:
    stand = [mujoco_replay.STAND[n] for n in mujoco_replay.SERVOS]
    o = mujoco_replay.simulate(np.array([0.0, 2.0]), np.array([stand, stand]))
    assert not o.fell, o
    assert abs(o.dx) < 0.001 and max(abs(d) for d in o.foot_dx) < 0.001, o
    assert max(o.lift) < 0.001, o


def test_the_model_weighs_what_the_built_in_one_does() -> None:
    # 4.996 kg in all (the H25 V3.3 whole robot), the lumped torso 2.74988 kg (by hand: 4.996 less
    # twice 0.1353 + 0.39421 + 0.29159 + 0.13892 + 0.16304 = 1.12306).
    import mujoco

    model = mujoco.MjModel.from_xml_string(mujoco_replay.model_xml(0.0005, 50.0))
    assert abs(sum(model.body_mass) - 4.996) < 1e-9
    assert abs(model.body_mass[model.body("torso").id] - 2.74988) < 1e-9
