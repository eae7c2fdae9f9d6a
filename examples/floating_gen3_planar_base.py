"""A Kinova Gen3 on a holonomic planar base (``Tree.from_urdf(..., base="planar")``: x, y and yaw
in the floor's plane, unactuated here) swinging its first joint with a constant torque.

The URDF gets a 40 kg platform under the arm's base link, the arm mounted 0.2 m off its centre
(the platform is the tree's root link: its inertia and the arm's base link's make the base body).
The arm's other joints hold their pose against gravity (``gravity_torques``, recomputed each step
by the controller). The floor only pushes normal to the plane, so the horizontal momentum and the
angular momentum about the vertical stay zero: the platform recoils and turns against the arm,
and the centre of mass does not move in x-y. The script prints the base's motion and the centre
of mass's horizontal drift (first order in the step) and the mass matrix's base block.

Run: ``python examples/floating_gen3_planar_base.py [out_dir]`` (prints only; about 1 s).
"""

import numpy as np

import vereshchagin as vs
from vereshchagin.robots import gen3_urdf

DT, DURATION, TORQUE = 1e-3, 1.0, 3.0  # s, s, N m on joint 1
PLATFORM = """<link name="platform"><inertial><origin xyz="0 0 -0.1"/><mass value="40"/>
  <inertia ixx="1.2" iyy="1.2" izz="1.6" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="platform_mount" type="fixed"><parent link="platform"/><child link="base_link"/>
  <origin xyz="0.2 0 0"/></joint>
"""

text = gen3_urdf(gripper=False)
text = text.replace('<link name="base_link">', PLATFORM + '<link name="base_link">', 1)
tree = vs.Tree.from_urdf(text, base="planar")
print(f"Gen3 on a planar base: nq = {tree.nq} (x, y, cos, sin, joints), nv = {tree.nv} (v_x, v_y, omega_z, joints)")

q = np.zeros(tree.nq)
q[2] = 1.0  # yaw 0
q[4:] = [0.0, 0.5, 0.0, 1.5, 0.0, 0.6, 0.0]  # the arm reaching forward
H = tree.mass_matrix(q)
print(f"base block of H: mass {H[0, 0]:.3f} kg, inertia about the vertical {H[2, 2]:.3f} kg m^2")


def controller(t, q, qd):
    """Joint 1 driven with TORQUE, the other joints held against gravity; nothing on the base rows."""
    tau = tree.gravity_torques(q)
    tau[:3] = 0.0  # the base has no motor
    tau[3] += TORQUE
    return {"tau_ff": tau}


sim = vs.Simulator(tree, DT, q=q)
c0 = tree.center_of_mass(q)
out = sim.rollout(round(DURATION / DT), controller=controller)
print("   t (s)   base x (mm)   base y (mm)   yaw (deg)   joint 1 (deg)   COM x-y drift (mm)")
for k in range(0, len(out["t"]), 200):
    qk = out["q"][k]
    drift = np.linalg.norm(tree.center_of_mass(qk)[:2] - c0[:2])
    yaw = np.degrees(np.arctan2(qk[3], qk[2]))
    print(
        f"{out['t'][k]:8.3f}   {1e3 * qk[0]:11.3f}   {1e3 * qk[1]:11.3f}   {yaw:9.3f}   "
        f"{np.degrees(qk[4]):13.3f}   {1e3 * drift:18.2e}"
    )
h = tree.centroidal_momentum(out["q"][-1], out["qd"][-1])
print(f"at the end: horizontal momentum ({h[0]:.2e}, {h[1]:.2e}) kg m/s, about the vertical {h[5]:.2e} kg m^2/s")
