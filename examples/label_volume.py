#!/usr/bin/python3
"""A 3D label volume -> a scene -> a run (docs/python.md).

    examples/label_volume.py [LABELS.nii[.gz] SCALE] [--out DIR] [--steps N]

Without a file, a synthetic 4-cell "embryo" is drawn as a label array: four
ellipsoids in the egg's ellipsoid, in micrometres on a 1.5 um grid.  With a
file (nibabel reads it), its labels and voxel sizes are used the same way.
The array goes into the scene's ``initial`` with softpack.label_initial (the
package writes it to a temporary NIfTI-1 file that initial.label_volume
reads), mapped into mesh units (1 unit = 100 um: scale 0.01) and centred in
the egg; then each step's cells are printed.
"""
import argparse

import numpy as np

import softpack


def synthetic_embryo(h=1.5):
    """Four touching ellipsoids (labels 10, 20, 30, 40) in a 50 x 30 x 30 um
    egg, on an h-micrometre grid indexed [x, y, z]."""
    n = (int(56 / h), int(30 / h), int(30 / h))
    x, y, z = np.meshgrid(*[(np.arange(m) - (m - 1) / 2) * h for m in n], indexing="ij")
    labels = np.zeros(n, np.uint8)
    # (label, centre, semi-axes) in um: ABa/ABp anterior, EMS/P2 posterior
    for label, c, s in ((10, (-13, 5, 0), (10, 8, 9)), (20, (-9, -9, 0), (9, 7, 9)),
                        (30, (9, 6, 0), (9, 8, 8)), (40, (15, -7, 0), (8, 7, 8))):
        inside = sum(((a - ca) / sa) ** 2 for a, ca, sa in zip((x, y, z), c, s)) < 1
        labels[inside & (labels == 0)] = label
    return labels, (h, h, h)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("volume", nargs="?", help="a NIfTI label volume (needs nibabel)")
    p.add_argument("scale", nargs="?", type=float, default=0.01,
                   help="mesh length per unit of the volume's coordinates (default 0.01)")
    p.add_argument("--out", default="out/label_volume")
    p.add_argument("--steps", type=int, default=5, help="time.max_steps (default 5)")
    p.add_argument("--refinements", type=int, default=2, help="mesh.refinements (default 2)")
    a = p.parse_args()

    if a.volume:
        import nibabel
        img = nibabel.load(a.volume)
        labels = np.asarray(img.dataobj).astype(np.int64)
        spacing = img.header.get_zooms()[:3]
    else:
        labels, spacing = synthetic_embryo()
    print(f"labels: {labels.shape} voxels of {spacing}, cells {np.unique(labels[labels > 0])}")

    scene = {
        "mesh": {"type": "ellipsoid", "refinements": a.refinements, "semi_x": 0.3,
                 "semi_y": 0.18, "semi_z": 0.18, "buffer_layers": 2, "buffer_width": 0.06},
        "model": {"alpha": 4, "kappa": 1.0e-3, "lambda": 100, "lambda_b": 100},
        "time": {"t_end": 0.01, "max_steps": a.steps},
        "division": {"criterion": "none"},
        "output": {"pictures": False},
        # the labels' bounding box centred at the origin, 1 um = 0.01
        "initial": softpack.label_initial(labels, spacing=spacing, origin=(0, 0, 0),
                                          scale=a.scale, centre=True),
    }

    def show(s):
        print(f"step {s.step:3d} t {s.t:.3e} dt {s.dt:.2e}  volumes "
              + " ".join(f"{v:.4f}" for v in s.volumes)
              + "  long axes " + " ".join(f"{s.moments[k, 0] / s.moments[k, 2]:.2f}"
                                         for k in range(s.n_cells)))

    result = softpack.run(scene, out=a.out, on_step=show)
    print(result)
    cells = result.cells
    last = cells[cells["step"] == cells["step"].max()]  # (a DataFrame, or numpy rows)
    print("last step's cells (cells.csv):")
    print(last)


if __name__ == "__main__":
    main()
