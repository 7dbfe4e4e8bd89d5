"""comm=: np = 2 under mpiexec with mpi4py gives the outputs of np = 1
(to round-off: the sums of two ranks' parts), and every rank's callback
sees the same steps."""
import os
import shlex
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("mpi4py")

MPIEXEC = os.environ.get("SOFTPACK_MPIEXEC") or "mpiexec"
PREFLAGS = shlex.split(os.environ.get("SOFTPACK_MPI_PREFLAGS", ""))
if not PREFLAGS and os.geteuid() == 0:
    PREFLAGS = ["--allow-run-as-root", "--oversubscribe"]
HERE = os.path.dirname(os.path.abspath(__file__))


def mpirun(np_, out, how="comm"):
    env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_MCA_mpi_yield_when_idle="1",
               PYTHONPATH=os.pathsep.join([HERE, os.environ.get("PYTHONPATH", "")]))
    cmd = [MPIEXEC, "-n", str(np_), *PREFLAGS, sys.executable, os.path.join(HERE, "mpi_run.py"),
           str(out), how]
    p = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=240)
    assert p.returncode == 0, p.stdout + p.stderr


def table(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
        rows = [[float(x) if x else np.nan for x in line.strip().split(",")] for line in f]
    return header, np.array(rows)


def test_np2_equals_np1(tmp_path):
    mpirun(1, tmp_path / "np1")
    mpirun(2, tmp_path / "np2")
    for name in ("cells.csv", "contacts.csv"):
        h1, a = table(tmp_path / "np1" / name)
        h2, b = table(tmp_path / "np2" / name)
        assert h1 == h2 and a.shape == b.shape, name
        assert np.allclose(a, b, rtol=1e-9, atol=1e-12, equal_nan=True), name
    h, a = table(tmp_path / "np1" / "energy.csv")
    _, b = table(tmp_path / "np2" / "energy.csv")
    for col in ("step", "t", "dt", "n_cells", "energy", "newton_its"):
        j = h.index(col)
        assert np.allclose(a[:, j], b[:, j], rtol=1e-9), col
    ranks = [(tmp_path / "np2" / f"rank{r}.txt").read_text() for r in (0, 1)]
    assert ranks[0] == ranks[1] and ranks[0].endswith("steps 6 size 2\n")
    one = (tmp_path / "np1" / "rank0.txt").read_text().splitlines()
    assert len(one) == 7 and [line.split()[0] for line in one[:6]] == [str(s) for s in range(1, 7)]
    # the fields of two ranks' pieces (.pvtu) read back as one mesh
    import softpack
    f1 = softpack.read_vtu(str(tmp_path / "np1" / "fields_000006.vtu"))
    f2 = softpack.read_vtu(str(tmp_path / "np2" / "fields_000006.pvtu"))
    assert np.array_equal(f1.points, f2.points)
    assert np.allclose(f1.c(1), f2.c(1), rtol=1e-9, atol=1e-12)


def test_world_without_comm(tmp_path):
    """comm=None under mpiexec: MPI_COMM_WORLD, the same run."""
    mpirun(2, tmp_path / "world", how="world")
    assert (tmp_path / "world" / "rank1.txt").read_text().endswith("steps 6 size 2\n")


def test_comm_self_runs_apart(tmp_path):
    """comm=MPI.COMM_SELF under mpiexec -n 2: two one-process runs at once,
    each as the one-process run (a sweep spread over ranks)."""
    mpirun(2, tmp_path / "self", how="self")
    mpirun(1, tmp_path / "np1")
    _, a = table(tmp_path / "np1" / "cells.csv")
    for r in (0, 1):
        _, b = table(tmp_path / "self" / f"self{r}" / "cells.csv")
        assert np.array_equal(a, b, equal_nan=True)
