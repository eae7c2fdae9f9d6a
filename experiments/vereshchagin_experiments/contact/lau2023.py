"""The published numbers of W. K. Lau (2023) that the contact report prints next to the simulation.

W. K. Lau, "Exploiting contact constraints in robotic manipulation tasks", R&D project report,
Hochschule Bonn-Rhein-Sieg, 2023, sec. 6.2-6.3. Joints are counted from 0 there (0 .. 6, base to
wrist); the contact report counts them the same way.

- Table 6.1 (use case 1): average bus voltage (V), current (A) and "power consumption" (W) per
  joint; the power is the average of ``P_i = V_i * I_i`` with the signed current, so it is no
  energy measure: it follows the signed motor torque (current ~ torque) times a nearly constant
  bus voltage (about 23.3 V; the contact voltage 3.1786 V of joint 2 is a misprint, its power
  1.4536 W = 23.2 V * 0.0626 A). Only joint 6 contactless, whose tiny current changes sign,
  has a power of the other sign than its average current.
- Table 6.2 (use case 1): average signed torque (N m) per joint. Its text says "the contact case
  exhibits an average torque of 1.9857 N, while the contactless case ... 0.8256 N": the table's
  own seven values average to the reverse (contact 0.8256, contactless 1.9858 N m).
- Table 6.3 (use case 2): maximum and average y displacement (m) of the written line.
"""

from __future__ import annotations

import numpy as np

__all__ = ["KEY_JOINTS", "LAU_2023", "table_means"]

LAU_2023 = {
    # Table 6.2, average torque (N m) per joint 0..6: contact, contactless
    "torque_contact": (0.2164, 9.8474, 0.3025, -3.1071, 0.3014, -1.7027, -0.0787),
    "torque_contactless": (-0.1564, 16.7563, 0.9884, -1.3727, 0.3063, -2.5120, -0.1095),
    # Table 6.1, average electrical power V * I (W) per joint 0..6: contact, contactless
    "power_contact": (3.0093, -18.4433, 1.4536, 13.4307, 4.2983, 5.1487, -0.1950),
    "power_contactless": (-0.9776, -31.0272, 0.2443, 7.9853, 2.2659, 9.8156, 0.2994),
    # Table 6.1, average voltage (V) and signed current (A) per joint 0..6
    "voltage_contact": (23.4669, 23.3939, 3.1786, 23.2972, 23.3074, 23.2875, 23.1337),
    "voltage_contactless": (23.4727, 23.3541, 23.1764, 23.2945, 23.2133, 23.2839, 23.1356),
    "current_contact": (0.1283, -0.7882, 0.0626, 0.5766, 0.1844, 0.2210, -0.0084),
    "current_contactless": (-0.0416, -1.3291, 0.0104, 0.3427, 0.0976, 0.4215, -0.0129),
    # Table 6.3, writing (m): max displacement, average displacement
    "writing_contact": (0.00211145, -0.00120878),
    "writing_contactless": (0.00089509, 0.00034292),
    # Sec. 6.2 text: all-joint average torque as printed (N m; swapped against Table 6.2)
    "text_all_joint_torque": {"contact": 1.9857, "contactless": 0.8256},
}
"""Published numbers of W. K. Lau (2023), joints counted from 0 (module doc)."""

KEY_JOINTS = {1: "shoulder", 3: "elbow", 5: "wrist"}
"""The joints the report discusses (counted from 0) and their names."""


def table_means() -> dict:
    """All-joint averages of Table 6.2 (N m): ``{"signed": (contact, contactless), "abs": (...)}``."""
    c, n = np.array(LAU_2023["torque_contact"]), np.array(LAU_2023["torque_contactless"])
    return {"signed": (float(c.mean()), float(n.mean())), "abs": (float(np.abs(c).mean()), float(np.abs(n).mean()))}
