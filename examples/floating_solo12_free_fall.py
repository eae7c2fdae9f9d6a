"""A solo12 quadruped on a free-flyer base (``Tree.from_urdf(..., base="free")``), tossed upwards
with a spin and simulated in free flight by ``vs.Simulator``.

Nothing but gravity acts on it, so its centre of mass follows the parabola ``c0 + v0 t + g t^2 / 2``
and its angular momentum about the centre of mass stays constant while the body tumbles and the
legs swing (their motors give no torque). The script prints both against the simulation (the
step is first order: the errors shrink with dt), and the base's quaternion norm.

Run: ``python examples/floating_solo12_free_fall.py [out_dir]`` (prints only; about 1 s).
"""

import numpy as np

import vereshchagin as vs
from vereshchagin.robots import example_robot_urdf

GRAVITY = np.array([0.0, 0.0, -9.81])
DT, DURATION = 1e-3, 0.6  # s

tree = vs.Tree.from_urdf(example_robot_urdf("solo_description/robots/solo12.urdf"), base="free")
print(f"solo12: {tree.n_joints} joints, base '{tree.base}', nq = {tree.nq}, nv = {tree.nv}")

q = np.zeros(tree.nq)
q[2], q[6] = 0.3, 1.0  # the base 0.3 m up, unrotated (quaternion x, y, z, w)
q[7:] = np.tile([0.0, 0.8, -1.6], 4)  # the legs folded
qd = np.zeros(tree.nv)
qd[:3] = [0.5, 0.0, 3.0]  # base velocity, m/s (base axes)
qd[3:6] = [0.0, 2.0, 1.0]  # base angular velocity, rad/s (base axes)
qd[7::3] = 1.5  # the thighs swinging

sim = vs.Simulator(tree, DT, gravity=GRAVITY, q=q, qd=qd)
out = sim.rollout(round(DURATION / DT))
c0, v0 = tree.center_of_mass(q), tree.center_of_mass_velocity(q, qd)
L0 = tree.centroidal_momentum(q, qd)[3:]
print(f"total mass {tree.centroidal_momentum(q, qd)[0] / v0[0]:.3f} kg")
print("   t (s)   COM height (m)  parabola (m)   |L_G - L_G(0)| (kg m^2/s)   |quaternion| - 1")
for k in range(0, len(out["t"]), 100):
    t, qk, qdk = out["t"][k], out["q"][k], out["qd"][k]
    c = tree.center_of_mass(qk)
    parabola = c0 + v0 * t + 0.5 * GRAVITY * t**2
    dL = np.linalg.norm(tree.centroidal_momentum(qk, qdk)[3:] - L0)
    print(f"{t:8.3f}   {c[2]:12.6f}   {parabola[2]:12.6f}   {dL:22.2e}   {np.linalg.norm(qk[3:7]) - 1:14.1e}")
turn = 2 * np.degrees(np.arccos(min(1.0, abs(out["q"][-1][6]))))
print(
    f"the base turned by {turn:.1f} degrees; COM error at the end "
    f"{np.linalg.norm(tree.center_of_mass(out['q'][-1]) - c0 - v0 * DURATION - 0.5 * GRAVITY * DURATION**2):.2e} m"
)
