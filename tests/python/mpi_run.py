"""Run by test_mpi.py under mpiexec: the small scene on mpi4py's
COMM_WORLD into OUT, each rank's step callback's steps and masses into
OUT/rank<r>.txt.   mpi_run.py OUT [comm|world|self]
(self: every rank its own one-process run on COMM_SELF into OUT/self<r>,
as a parameter sweep spread over the ranks does.)"""
import os
import sys

from mpi4py import MPI

import softpack
from conftest import SMALL

out, how = sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "comm"
comm = MPI.COMM_WORLD
seen = []
scene = dict(SMALL, solver={"linear": "superlu_dist"})
if how == "self":
    r = softpack.run(scene, out=os.path.join(out, f"self{comm.rank}"), comm=MPI.COMM_SELF,
                     on_step=lambda s: seen.append(f"{s.step} {s.n_cells} {s.masses.sum():.12e}"))
else:
    r = softpack.run(scene, out=out, comm=comm if how == "comm" else None,
                     on_step=lambda s: seen.append(f"{s.step} {s.n_cells} {s.masses.sum():.12e}"))
comm.Barrier()
os.makedirs(out, exist_ok=True)
with open(os.path.join(out, f"rank{comm.rank}.txt"), "w") as f:
    f.write("\n".join(seen) + f"\nsteps {r.steps} size {comm.size}\n")
if how == "self":
    assert not any(n.startswith("fields") and n.endswith(".pvtu")
                   for n in os.listdir(os.path.join(out, f"self{comm.rank}")))
