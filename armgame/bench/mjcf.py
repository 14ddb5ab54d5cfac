"""The two-joint arm as a MuJoCo model, for the peer comparison.

The MJCF model uses armgame's frame directly: both hinges turn about +z, each body's x axis
runs along its link, so MuJoCo's qpos is (q1 from +x counter-clockwise, q2 relative to the
upper arm) exactly as ours, and gravity, when on, is set along -y. Inertials sit at r1 and r2
with the links' masses; only the z moment of inertia moves a planar arm, so all three
principal moments are i (which also satisfies MuJoCo's triangle inequality). Contacts are off.
"""

from __future__ import annotations

from typing import Any

from ..physics.params import TwoJointParams


def arm_mjcf(p: TwoJointParams, dt: float, integrator: str = "RK4") -> str:
    return f"""<mujoco model="armgame two-joint arm">
  <option timestep="{dt!r}" integrator="{integrator}" gravity="0 {-p.gravity!r} 0">
    <flag contact="disable"/>
  </option>
  <worldbody>
    <body name="upper_arm">
      <joint name="shoulder" type="hinge" axis="0 0 1" damping="{p.damping1!r}"/>
      <inertial pos="{p.r1!r} 0 0" mass="{p.m1!r}" diaginertia="{p.i1!r} {p.i1!r} {p.i1!r}"/>
      <body name="forearm" pos="{p.l1!r} 0 0">
        <joint name="elbow" type="hinge" axis="0 0 1" damping="{p.damping2!r}"/>
        <inertial pos="{p.r2!r} 0 0" mass="{p.m2!r}" diaginertia="{p.i2!r} {p.i2!r} {p.i2!r}"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def load_mujoco() -> Any | None:
    """The mujoco module, or None when the optional ``bench`` extra is not installed."""
    try:
        import mujoco
    except ImportError:
        return None
    # MuJoCo reports an unstable run by printing and writing MUJOCO_LOG.TXT in the working
    # folder; the bench detects blow-ups itself, so keep both quiet.
    mujoco.set_mju_user_warning(lambda _message: None)
    return mujoco


def build_model(mujoco: Any, p: TwoJointParams, dt: float, integrator: str = "RK4") -> tuple[Any, Any]:
    """(MjModel, MjData) for arm ``p`` stepped by ``integrator`` ("RK4" or "Euler") at ``dt``."""
    model = mujoco.MjModel.from_xml_string(arm_mjcf(p, dt, integrator))
    return model, mujoco.MjData(model)


def mass_matrix_and_bias(mujoco: Any, p: TwoJointParams, q: tuple[float, float], qd: tuple[float, float]) -> Any:
    """MuJoCo's M(q) (via mj_fullM) and bias forces C + G (qfrc_bias) at a state."""
    import numpy as np

    model, data = build_model(mujoco, p, 0.001)
    data.qpos[:] = q
    data.qvel[:] = qd
    mujoco.mj_forward(model, data)
    full = np.zeros((2, 2))
    mujoco.mj_fullM(model, data, full)
    return full, data.qfrc_bias.copy()
