#!/usr/bin/env python3
"""Python benchmark: the per-call time of ``vs.whole_body.least_effort`` (issue 28).

solo12 standing on its four point feet and Talos (reduced) on the four corners of each sole
(example-robot-data, free-flyer base), base still (six task rows on the base), mu 0.7, 4-facet
cones, qd = 0: the calls of tests/oracles/test_whole_body.py, which checks them against Pinocchio.
Each round times ``--calls`` calls on one Solver (after one warm-up call) and reports microseconds
per call; the median over ``--rounds`` rounds is printed, one line per robot, as
``<robot> <microseconds>``.

Before/after comparisons of the library run this script alternately under the two installs
(interleaved processes) and take the median of the per-pair ratios (BENCHMARKS.md, "Floating
bases", "Whole-body least effort per call").

Usage: python benchmarks/bench_whole_body.py [--rounds N] [--calls N]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

import vereshchagin as vs
from vereshchagin.robots import example_robot_urdf

GRAVITY = np.array([0.0, 0.0, -9.81])
BASE_STILL = (np.eye(6), np.r_[-GRAVITY, 0.0, 0.0, 0.0])


def solo12():
    tree = vs.Tree.from_urdf(example_robot_urdf("solo_description/robots/solo12.urdf"), base="free")
    legs = {"FL": (0.1, 0.8, -1.6), "FR": (-0.1, 0.8, -1.6), "HL": (0.1, -0.8, 1.6), "HR": (-0.1, -0.8, 1.6)}
    joints = {f"{leg}_{j}": v for leg, vals in legs.items() for j, v in zip(("HAA", "HFE", "KFE"), vals)}
    q = np.r_[0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 1.0, [joints[n] for n in tree.joint_names]]
    feet = [vs.Contact(f, normal=[0, 0, 1], mu=0.7) for f in ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")]
    return tree, q, feet


def talos():
    tree = vs.Tree.from_urdf(example_robot_urdf("talos_data/robots/talos_reduced.urdf"), base="free")
    half = {"leg_left_3_joint": -0.4, "leg_left_4_joint": 0.8, "leg_left_5_joint": -0.4}
    half.update({k.replace("left", "right"): v for k, v in half.items()})
    q = np.r_[0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, [half.get(n, 0.0) for n in tree.joint_names]]
    corners = ((0.1, 0.05, 0.0), (0.1, -0.05, 0.0), (-0.1, 0.05, 0.0), (-0.1, -0.05, 0.0))
    feet = [
        vs.Contact(s, point=c, normal=[0, 0, 1], mu=0.7) for s in ("left_sole_link", "right_sole_link") for c in corners
    ]
    return tree, q, feet


def per_call_us(tree, q, feet, calls):
    solver = vs.Solver(tree, gravity=GRAVITY)
    qd = np.zeros(tree.nv)
    task = {None: BASE_STILL}
    vs.whole_body.least_effort(solver, q, qd, task=task, supports=feet)  # warm-up
    start = time.perf_counter()
    for _ in range(calls):
        vs.whole_body.least_effort(solver, q, qd, task=task, supports=feet)
    return (time.perf_counter() - start) / calls * 1e6


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--calls", type=int, default=200)
    args = parser.parse_args()
    for name, make in (("solo12", solo12), ("talos", talos)):
        tree, q, feet = make()
        times = [per_call_us(tree, q, feet, args.calls) for _ in range(args.rounds)]
        print(f"{name} {statistics.median(times):.2f}")


if __name__ == "__main__":
    main()
