"""A parameter sweep in parallel with Dask: how much must the motors add to hold the Gen3's tool
still, as a function of the shoulder angle and of the joints' breakaway friction?

Every grid point is one independent task (build the chain, solve with friction, return a
number), submitted to a ``dask.distributed`` client. Here the client starts a small
``LocalCluster`` (2 workers in this process: the solver releases the GIL); pointing ``Client`` at
a scheduler address runs the same code on a real cluster. Each task gets plain numbers and builds
its own solver, so nothing but floats crosses the network.

Run: ``python examples/dask_parameter_sweep.py [out_dir] [scheduler_address]``
(writes dask_parameter_sweep.png; about 5 s including the cluster start; needs ``dask`` and
``distributed``).
"""

import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from dask.distributed import Client, LocalCluster

import vereshchagin as vs

FRICTION = np.linspace(0.0, 20.0, 11)  # breakaway friction of every joint, N m
SHOULDER = np.linspace(-1.0, 1.0, 9)  # offset of joint 2 from the start pose, rad


def holding_command(shoulder_offset, friction):
    """|tau_command| (N m) to hold the tool still at rest, with breakaway friction on every joint."""
    chain = vs.robots.gen3()
    solver = vs.Solver(chain)
    q = np.array(vs.robots.GEN3_START_POSE)
    q[1] += shoulder_offset
    qd = np.zeros(chain.n_joints)
    task = vs.task.Task(["x", "y", "z", "rx", "ry", "rz"])
    res = task.solve(solver, chain, q, qd, np.zeros(6), friction=vs.Friction(static=np.full(7, friction)))
    return float(np.linalg.norm(res.tau_command))


def sweep(client):
    """The grid, one Dask task per point; returns (len(SHOULDER), len(FRICTION)) norms."""
    grid = [(s, f) for s in SHOULDER for f in FRICTION]
    futures = client.map(holding_command, [s for s, _ in grid], [f for _, f in grid])
    return np.array(client.gather(futures)).reshape(len(SHOULDER), len(FRICTION))


def main(out_dir=".", address=None):
    if address is None:
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None)
        client = Client(cluster)
    else:
        cluster, client = None, Client(address)
    try:
        table = sweep(client)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    # Spot check: the parallel result equals a sequential evaluation.
    assert table[4, 3] == holding_command(SHOULDER[4], FRICTION[3])
    print(f"{table.size} grid points solved on {'a LocalCluster' if address is None else address}")
    print("shoulder offset [rad] -> friction [N m] at which the motors need nothing:")
    for s, row in zip(SHOULDER, table):
        held = FRICTION[row < 1e-9]
        print(f"  {s:+.2f}: {'more than ' + str(FRICTION[-1]) if held.size == 0 else f'{held[0]:.0f}'}")
    fig, ax = plt.subplots(figsize=(7, 4.5))
    image = ax.imshow(
        table,
        origin="lower",
        aspect="auto",
        cmap="viridis",
        extent=[FRICTION[0], FRICTION[-1], SHOULDER[0], SHOULDER[-1]],
    )
    fig.colorbar(image, label="|tau_command| to hold the tool [N m]")
    ax.set_xlabel("breakaway friction of every joint [N m]")
    ax.set_ylabel("shoulder (joint 2) offset [rad]")
    ax.set_title("Gen3 at rest, tool held still: motor effort left over by static friction")
    fig.tight_layout()
    out = Path(out_dir) / "dask_parameter_sweep.png"
    fig.savefig(out, dpi=100)
    plt.close(fig)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(*sys.argv[1:])
