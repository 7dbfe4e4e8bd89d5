"""Initial cells from numpy label arrays: the same run as the label image
(PNG) or label volume (NIfTI) twin the scene keys read, same outputs."""
import numpy as np
import pytest

import softpack

SETS = {"time.max_steps": 2, "mesh.refinements": 3, "output.pictures": False}


def same_outputs(a, b):
    for name in ("cells", "contacts"):
        x, y = getattr(a, name), getattr(b, name)
        assert list(x.columns) == list(y.columns) if hasattr(x, "columns") else True
        for col in (x.columns if hasattr(x, "columns") else x.dtype.names):
            assert np.array_equal(np.asarray(x[col], float), np.asarray(y[col], float),
                                  equal_nan=True), (name, col)
    for col in ("step", "t", "dt", "energy", "bulk", "gradient", "repulsion", "n_cells"):
        assert np.array_equal(np.asarray(a.energy[col]), np.asarray(b.energy[col])), col


def test_png_reader_writer_round_trip(source_dir, tmp_path):
    labels = softpack.read_label_image(f"{source_dir}/inputs/labels/embryo_4.png")
    assert labels.shape == (200, 100) and set(np.unique(labels)) == {0, 1, 2, 3, 4}
    softpack.write_label_png(str(tmp_path / "again.png"), labels[:, ::-1].T)
    assert np.array_equal(softpack.read_label_image(str(tmp_path / "again.png")), labels)


def test_label_array_2d_is_its_png_twin(source_dir, tmp_path):
    """inputs/label_image.yaml (the PNG on x in [-0.5, 0.5], y in [-0.25,
    0.25]) against the same scene with the PNG's labels as an array."""
    png = softpack.run(f"{source_dir}/inputs/label_image.yaml", out=tmp_path / "png",
                       overrides=SETS)
    labels = softpack.read_label_image(f"{source_dir}/inputs/labels/embryo_4.png")
    h = (1.0 / 200, 0.5 / 100)
    scene = {"mesh": {"type": "ellipse", "refinements": 5, "semi_x": 0.5, "semi_y": 0.25,
                      "buffer_layers": 2, "buffer_width": 0.1},
             "time": {"t_end": 0.004}, "output": {"every": 10},
             "initial": softpack.label_initial(labels, spacing=h,
                                               origin=(-0.5 + h[0] / 2, -0.25 + h[1] / 2))}
    arr = softpack.run(scene, out=tmp_path / "array", overrides=SETS)
    assert png.n_cells == arr.n_cells == 4
    same_outputs(png, arr)
    # the labels, not their file, in the scene: nothing left behind
    assert not any(p.suffix == ".png" for p in (tmp_path / "array").iterdir()
                   if p.name.startswith("labels"))


def two_blobs(n=20, h=0.03):
    i, j, k = np.meshgrid(*(np.arange(n),) * 3, indexing="ij")
    x, y, z = [(a - (n - 1) / 2) * h for a in (i, j, k)]
    labels = np.zeros((n, n, n), np.uint16)
    labels[((x + 0.12) / 0.12) ** 2 + (y / 0.1) ** 2 + (z / 0.1) ** 2 < 1] = 7
    labels[((x - 0.12) / 0.1) ** 2 + (y / 0.1) ** 2 + (z / 0.09) ** 2 < 1] = 3
    affine = np.diag([h, h, h, 1.0])
    affine[:3, 3] = -(n - 1) / 2 * h
    return labels, h, affine


BOX = {"mesh": {"type": "box", "x0": -0.3, "y0": -0.3, "z0": -0.3, "x1": 0.3, "y1": 0.3,
                "z1": 0.3, "nx": 8, "ny": 8, "nz": 8},
       "model": {"kappa": 4e-3}, "time": {"max_steps": 2, "dt": 2e-4},
       "output": {"pictures": False}}


def test_label_array_3d_is_its_nifti_twin(tmp_path):
    """The volume written by nibabel (an independent writer) against the
    same array given to run(); cells in ascending label order (3, 7)."""
    nib = pytest.importorskip("nibabel")
    labels, h, affine = two_blobs()
    nib.save(nib.Nifti1Image(labels, affine), str(tmp_path / "twin.nii"))
    a = softpack.run(dict(BOX, initial={"label_volume": str(tmp_path / "twin.nii")}),
                     out=tmp_path / "nii")
    b = softpack.run(dict(BOX, initial=softpack.label_initial(labels, spacing=h)),
                     out=tmp_path / "array")
    assert a.n_cells == b.n_cells == 2
    same_outputs(a, b)
    xc = np.asarray(b.cells["xc"], float)[:2]
    assert xc[0] > 0.05 and xc[1] < -0.05      # label 3 at +x is cell 1, label 7 cell 2


def test_label_array_3d_placement_keys(tmp_path):
    """scale and offset_* pass through to the volume's keys: spacing in
    file units times initial.scale, the file's origin at the offset."""
    labels, h, _ = two_blobs()
    o = -(20 - 1) / 2 * h
    b = softpack.run(dict(BOX, initial=softpack.label_initial(
        labels, spacing=h * 100, origin=(0, 0, 0), scale=0.01, offset_x=o + 0.02, offset_y=o,
        offset_z=o)), out=tmp_path / "placed")
    c = softpack.run(dict(BOX, initial=softpack.label_initial(labels, spacing=h,
                                                              origin=(o + 0.02, o, o))),
                     out=tmp_path / "direct")
    for col in ("mass", "xc", "yc"):
        assert np.allclose(np.asarray(b.cells[col], float), np.asarray(c.cells[col], float),
                           rtol=1e-3, atol=1e-6), col  # (the sform is float32)


def test_bad_label_arrays(small, tmp_path):
    for bad, match in ((np.zeros(5), "2D or 3D"), (-np.ones((4, 4)), ">= 0"),
                       (np.full((4, 4), 0.5), "integer")):
        small["initial"] = softpack.label_initial(bad, spacing=0.1)
        small.pop("cells", None)
        with pytest.raises(ValueError, match=match):
            softpack.run(small, out=tmp_path / "never")
    # the library's own check: a label image with no labels
    small["initial"] = softpack.label_initial(np.zeros((4, 4), int), spacing=0.1)
    with pytest.raises(softpack.SceneError) as e:
        softpack.run(small, out=tmp_path / "never")
    assert e.value.key == "initial.label_image"
    assert not (tmp_path / "never").exists()
