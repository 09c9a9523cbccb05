#!/usr/bin/env python3
"""The second engine: replays ga_step motions in MuJoCo, to confirm what the built-in physics
(rapier3d, `physics: webots`) says of them.

    .venv/bin/python tests/mujoco_replay.py MOTION_FILE... [--dt 0.0005] [--kv 50]

A MOTION_FILE is a Webots motion file as ga_step writes it (`#WEBOTS_MOTION,V1.0,` and the ten
leg servos, a row every 40 ms from 0 to T). The robot is the same Nao as the built-in evaluator's,
written here as MJCF from the same link table (docs/ga_step.md, "Calibration"); the servos are
Webots' position control (V = P·(target − angle), P = 10, clamped to maxVelocity) driven by a
velocity actuator of gain `kv` capped at maxTorque; the floor contact has μ = 7 and ODE's
softness (20.1 Hz, damping ratio 5.06). The motion plays for T, then the standing pose is held
to T + 1 s; a fall ends it, by the built-in evaluator's rule: the torso frame below 0.20 m,
tilted beyond 0.5 rad, or a body but the feet touching the floor. Prints one line per motion:
the verdict, the time, the torso's Δx and each foot's lift and forward move; the exit status is 0.

Independent of the built-in evaluator: MuJoCo's soft-contact solver and integrator, its own
inertias from the same shapes and masses, and a smaller time step (0.5 ms by default).
"""
from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

# The link table of mobil_ga_step_sim's BodyParams::webots (m, kg).
HIP_Y, HIP_Z = 0.050, 0.085
THIGH, TIBIA = 0.100, 0.1029
FOOT_HEIGHT, FOOT_LENGTH, FOOT_WIDTH = 0.046, 0.147, 0.089
FOOT_FORWARD, FOOT_OUTWARD, SOLE = 0.020, 0.007, 0.010
LIMB_R, BALL_R = 0.030, 0.020
MASS = {"hip": 0.13530, "thigh": 0.39421, "tibia": 0.29159, "ankle": 0.13892, "foot": 0.16304}
WHOLE = 4.996
TORSO_MASS = WHOLE - 2 * sum(MASS.values())
TORSO_COM_Z = 0.060
TORSO_BOX = (0.10, 0.20, 0.30)
# Webots' motors (Nao.proto V3.3, RotationalMotor.wrl) and world (nao_robocup.wbt).
P_GAIN = 10.0
PITCH_TORQUE, ROLL_TORQUE = 8.0, 12.0
PITCH_SPEED, ROLL_SPEED = 6.40239, 4.16174
MU = 7.0
CONTACT_HZ, CONTACT_ZETA = 20.1, 5.06
# The genome's servos (SPEC §8) with Table 1's limits, and the default standing pose and fall rule
# of params/nao_step.yaml.
SERVOS = ["RHipPitch", "RHipRoll", "RKneePitch", "RAnklePitch", "RAnkleRoll",
          "LHipPitch", "LHipRoll", "LKneePitch", "LAnklePitch", "LAnkleRoll"]
LIMITS = {
    "RHipPitch": (-1.7453, 0.4363), "LHipPitch": (-1.7453, 0.4363),
    "RHipRoll": (-0.7854, 0.4363), "LHipRoll": (-0.4363, 0.7854),
    "RKneePitch": (0.0, 2.2689), "LKneePitch": (0.0, 2.2689),
    "RAnklePitch": (-1.309, 0.7854), "LAnklePitch": (-1.309, 0.7854),
    "RAnkleRoll": (-0.4363, 0.7854), "LAnkleRoll": (-0.7854, 0.4363),
}
STAND = dict(zip(SERVOS, [-0.4, 0.0, 0.8, -0.4, 0.0, -0.4, 0.0, 0.8, -0.4, 0.0]))
SETTLE, FALL_HEIGHT, FALL_TILT = 1.0, 0.20, 0.5


def is_roll(name: str) -> bool:
    return "Roll" in name


def leg_xml(side: str) -> str:
    """One leg, from the hip joint down, every joint at zero with the leg straight (Nao's zero)."""
    s = 1.0 if side == "L" else -1.0
    sx, sy = FOOT_FORWARD, s * FOOT_OUTWARD
    foot_z = -FOOT_HEIGHT + SOLE / 2
    return f"""
      <body name="{side}hip" pos="0 {s * HIP_Y} {-HIP_Z}">
        <joint name="{side}HipRoll" axis="1 0 0"/>
        <geom name="{side}hip_ball" type="sphere" size="{BALL_R}" mass="{MASS['hip']}"/>
        <body name="{side}thigh">
          <joint name="{side}HipPitch" axis="0 1 0"/>
          <geom name="{side}thigh_geom" type="capsule" fromto="0 0 {-LIMB_R} 0 0 {-(THIGH - LIMB_R)}"
                size="{LIMB_R}" mass="{MASS['thigh']}"/>
          <body name="{side}tibia" pos="0 0 {-THIGH}">
            <joint name="{side}KneePitch" axis="0 1 0"/>
            <geom name="{side}tibia_geom" type="capsule" fromto="0 0 {-LIMB_R} 0 0 {-(TIBIA - LIMB_R)}"
                  size="{LIMB_R}" mass="{MASS['tibia']}"/>
            <body name="{side}ankle" pos="0 0 {-TIBIA}">
              <joint name="{side}AnklePitch" axis="0 1 0"/>
              <geom name="{side}ankle_ball" type="sphere" size="{BALL_R}" mass="{MASS['ankle']}"/>
              <body name="{side}foot">
                <joint name="{side}AnkleRoll" axis="1 0 0"/>
                <geom name="{side}sole" type="box" pos="{sx} {sy} {foot_z}"
                      size="{FOOT_LENGTH / 2} {FOOT_WIDTH / 2} {SOLE / 2}" mass="{MASS['foot']}"
                      friction="{MU} 0.005 0.0001"/>
              </body>
            </body>
          </body>
        </body>
      </body>"""


def model_xml(dt: float, kv: float) -> str:
    dx, dy, dz = TORSO_BOX
    box_z = dz / 2 - 0.04
    inertia = [TORSO_MASS * (b * b + c * c) / 12 for b, c in ((dy, dz), (dx, dz), (dx, dy))]
    # MuJoCo's direct contact reference, a_ref = -b·v - k·r per unit of effective mass: a spring
    # of natural frequency f and damping ratio ζ, whatever the mass (rapier's softness).
    w = 2 * math.pi * CONTACT_HZ
    solref = f"{-w * w:.1f} {-2 * CONTACT_ZETA * w:.1f}"
    actuators = "\n".join(
        f'    <velocity name="{n}" joint="{n}" kv="{kv}" forcelimited="true" '
        f'forcerange="{-(ROLL_TORQUE if is_roll(n) else PITCH_TORQUE)} {ROLL_TORQUE if is_roll(n) else PITCH_TORQUE}" '
        f'ctrllimited="false"/>'
        for n in SERVOS
    )
    return f"""<mujoco model="nao_legs">
  <option timestep="{dt}" integrator="implicitfast" gravity="0 0 -9.81" cone="elliptic"/>
  <default><geom solref="{solref}" solimp="0.95 0.95 0.001" condim="3"/></default>
  <worldbody>
    <geom name="floor" type="plane" size="50 50 0.1" friction="{MU} 0.005 0.0001"/>
    <body name="torso" pos="0 0 0.5">
      <freejoint/>
      <inertial pos="0 0 {TORSO_COM_Z}" mass="{TORSO_MASS}" diaginertia="{inertia[0]} {inertia[1]} {inertia[2]}"/>
      <geom name="torso_box" type="box" pos="0 0 {box_z}" size="{dx / 2} {dy / 2} {dz / 2}" mass="0"/>
      {leg_xml("R")}
      {leg_xml("L")}
    </body>
  </worldbody>
  <actuator>
{actuators}
  </actuator>
</mujoco>"""


def read_motion(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The rows' times (s) and angles (rad, genome order) of a Webots motion file."""
    lines = [l.strip() for l in path.read_text().splitlines() if l.strip()]
    header = lines[0].split(",")
    if not header[0].startswith("#WEBOTS_MOTION"):
        raise ValueError(f"{path}: not a Webots motion file")
    names = [h for h in header[2:] if h]
    columns = [names.index(n) for n in SERVOS]
    times, rows = [], []
    for line in lines[1:]:
        fields = line.split(",")
        m, s, ms = (int(x) for x in fields[0].split(":"))
        times.append(60 * m + s + ms / 1000)
        values = [float(v) for v in fields[2:2 + len(names)]]
        rows.append([values[c] for c in columns])
    return np.array(times), np.array(rows)


@dataclass
class Outcome:
    fell: bool
    cause: str
    t_end: float
    dx: float
    lift: tuple[float, float]
    foot_dx: tuple[float, float]

    def line(self, name: str) -> str:
        verdict = f"falls ({self.cause}) at {self.t_end:.2f} s" if self.fell else f"upright to {self.t_end:.2f} s"
        return (f"{name}: {verdict}, dx {self.dx:+.4f} m; right foot lifted {1e3 * self.lift[0]:.1f} mm, "
                f"moved {self.foot_dx[0]:+.4f} m; left foot lifted {1e3 * self.lift[1]:.1f} mm, moved {self.foot_dx[1]:+.4f} m")


def simulate(times: np.ndarray, rows: np.ndarray, dt: float = 0.0005, kv: float = 50.0,
             control_period: float = 0.0) -> Outcome:
    """Plays a motion; the servos' P-controller runs every `control_period` (s; 0: every step),
    its velocity held in between, as Webots holds it over a `basicTimeStep`."""
    model = mujoco.MjModel.from_xml_string(model_xml(dt, kv))
    data = mujoco.MjData(model)
    qadr = [model.jnt_qposadr[model.joint(n).id] for n in SERVOS]
    vadr = [model.jnt_dofadr[model.joint(n).id] for n in SERVOS]
    stand = np.array([STAND[n] for n in SERVOS])
    data.qpos[qadr] = stand
    # The lowest point on the floor: the torso lowered until the feet's lowest corner touches z = 0.
    mujoco.mj_kinematics(model, data)
    lowest = min(sole_corners(model, data, side)[:, 2].min() for side in "RL")
    data.qpos[2] -= lowest
    mujoco.mj_forward(model, data)
    floor = model.geom("floor").id
    feet = {model.geom("Rsole").id, model.geom("Lsole").id}
    torso = model.body("torso").id
    start_x = data.xpos[torso][0]
    start_feet = [sole_centre(model, data, s)[0] for s in "RL"]
    rest_z = [sole_corners(model, data, s)[:, 2].min() for s in "RL"]
    lift = [0.0, 0.0]
    step_time = float(times[-1])
    duration = step_time + SETTLE
    lo = np.array([LIMITS[n][0] for n in SERVOS])
    hi = np.array([LIMITS[n][1] for n in SERVOS])
    vmax = np.array([ROLL_SPEED if is_roll(n) else PITCH_SPEED for n in SERVOS])
    steps = int(round(duration / dt))
    every = max(1, int(round(control_period / dt)))
    out = Outcome(False, "", duration, 0.0, (0.0, 0.0), (0.0, 0.0))
    for n in range(1, steps + 1):
        t = n * dt
        target = stand if t >= step_time else np.array([np.interp(t, times, rows[:, j]) for j in range(len(SERVOS))])
        target = np.clip(target, lo, hi)
        if (n - 1) % every == 0:
            data.ctrl[:] = np.clip(P_GAIN * (target - data.qpos[qadr]), -vmax, vmax)
        mujoco.mj_step(model, data)
        z = data.xpos[torso][2]
        up = data.xmat[torso].reshape(3, 3)[:, 2]
        tilt = math.acos(max(-1.0, min(1.0, up[2])))
        for k, side in enumerate("RL"):
            lift[k] = max(lift[k], sole_corners(model, data, side)[:, 2].min() - rest_z[k])
        cause = ""
        if not np.isfinite(data.qpos).all():
            cause = "NonFinite"
        elif z < FALL_HEIGHT:
            cause = "Height"
        elif tilt > FALL_TILT:
            cause = "Tilt"
        else:
            for c in data.contact[: data.ncon]:
                other = c.geom2 if c.geom1 == floor else c.geom1 if c.geom2 == floor else None
                if other is not None and other not in feet and c.dist < 1e-3:
                    cause = "Contact"
                    break
        if cause:
            out.fell, out.cause, out.t_end = True, cause, t
            break
    out.dx = data.xpos[torso][0] - start_x
    out.lift = (lift[0], lift[1])
    out.foot_dx = tuple(sole_centre(model, data, s)[0] - x0 for s, x0 in zip("RL", start_feet))
    return out


def sole_box(model, data, side):
    g = model.geom(f"{side}sole").id
    return data.geom_xpos[g], data.geom_xmat[g].reshape(3, 3), model.geom_size[g]


def sole_centre(model, data, side) -> np.ndarray:
    pos, rot, size = sole_box(model, data, side)
    return pos + rot @ np.array([0.0, 0.0, -size[2]])


def sole_corners(model, data, side) -> np.ndarray:
    pos, rot, size = sole_box(model, data, side)
    return np.array([pos + rot @ np.array([sx * size[0], sy * size[1], -size[2]])
                     for sx in (-1, 1) for sy in (-1, 1)])


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("motions", nargs="+", type=Path)
    parser.add_argument("--dt", type=float, default=0.0005, help="MuJoCo's time step (s)")
    parser.add_argument("--kv", type=float, default=50.0, help="the velocity actuators' gain (N·m·s/rad)")
    parser.add_argument("--control-period", type=float, default=0.0,
                        help="the P-controller's period (s; 0: every step; Webots: its basicTimeStep)")
    args = parser.parse_args(argv)
    for path in args.motions:
        times, rows = read_motion(path)
        print(simulate(times, rows, args.dt, args.kv, args.control_period).line(str(path)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
