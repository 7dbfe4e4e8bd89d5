"""examples/: the notebook executed (nbconvert, or its code cells in order
as one script; small: SOFTPACK_EXAMPLE_QUICK=1, matplotlib's Agg backend),
and the label-volume script runs two steps."""
import json
import os
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR

EXAMPLES = os.path.join(SOURCE_DIR, "examples")


def env():
    return dict(os.environ, SOFTPACK_EXAMPLE_QUICK="1", MPLBACKEND="Agg",
                SOFTPACK_SOURCE_DIR=SOURCE_DIR, OMP_NUM_THREADS="1")


def notebook_code(path):
    """The notebook's code cells, in order, as one script (nbformat if
    present, else its JSON: a plain .ipynb)."""
    try:
        import nbformat
        nb = nbformat.read(path, as_version=4)
        nbformat.validate(nb)
        cells = [c.source for c in nb.cells if c.cell_type == "code"]
    except ImportError:
        with open(path) as f:
            nb = json.load(f)
        cells = ["".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "code"]
    return "\n\n".join(cells) + "\n"


def nbconvert_kernel():
    """True if nbconvert can execute the notebook here: nbconvert and a
    python3 kernel (Debian's python3-ipykernel) that imports numpy."""
    try:
        import nbconvert  # noqa: F401
        from jupyter_client.kernelspec import KernelSpecManager
        spec = KernelSpecManager().get_kernel_spec("python3")
    except Exception:  # noqa: BLE001 (any missing piece: run the code as a script)
        return False
    probe = subprocess.run([spec.argv[0], "-c", "import numpy, ipykernel"], capture_output=True)
    return probe.returncode == 0


def test_notebook(tmp_path):
    """Executed by nbconvert where it and a kernel are installed, else its
    code cells in order as one script; either way without network."""
    pytest.importorskip("matplotlib")
    pytest.importorskip("yaml")
    pytest.importorskip("pandas")
    notebook = os.path.join(EXAMPLES, "aspect_sweep.ipynb")
    if nbconvert_kernel():
        # (the kernel runs in the notebook's directory: a copy in tmp_path)
        copy = tmp_path / "aspect_sweep.ipynb"
        copy.write_text(open(notebook).read())
        cmd = [sys.executable, "-m", "nbconvert", "--to", "notebook", "--execute",
               "--output", "executed.ipynb", str(copy)]
    else:
        script = tmp_path / "aspect_sweep.py"
        script.write_text(notebook_code(notebook))
        cmd = [sys.executable, str(script)]
    p = subprocess.run(cmd, cwd=tmp_path, env=env(), capture_output=True, text=True,
                       timeout=240)
    assert p.returncode == 0, p.stdout + p.stderr
    out = tmp_path / "out" / "aspect_sweep"
    assert (out / "contact_graphs.png").stat().st_size > 1000
    assert (out / "cells.png").stat().st_size > 1000
    assert sum(1 for d in out.iterdir() if d.name.startswith("a_")) == 3
    printed = p.stdout
    if cmd[2:4] == ["nbconvert", "--to"]:
        with open(tmp_path / "executed.ipynb") as f:
            nb = json.load(f)
        printed = "".join("".join(o.get("text", "")) for c in nb["cells"]
                          if c["cell_type"] == "code" for o in c["outputs"])
    assert "4 cells" in printed


def test_label_volume_script(tmp_path):
    p = subprocess.run([sys.executable, os.path.join(EXAMPLES, "label_volume.py"),
                        "--steps", "2", "--out", str(tmp_path / "o")],
                       cwd=tmp_path, env=env(), capture_output=True, text=True, timeout=240)
    assert p.returncode == 0, p.stdout + p.stderr
    assert "step   2" in p.stdout and "2 steps" in p.stdout and "4 cells" in p.stdout
    assert (tmp_path / "o" / "cells.csv").exists()
