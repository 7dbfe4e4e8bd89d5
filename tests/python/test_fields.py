"""Fields as numpy arrays match what the run wrote: the .vtu reader's c_k
integrated over the mesh (2x2 / 2x2x2 Gauss on the Q1 elements) gives
cells.csv's masses and centres, in 2D and 3D; the
callback's StepInfo.field(k) and mesh() equal the .vtu of that step."""
import numpy as np
import pytest

import softpack


def gauss_integrals(fields, k, threshold=0.05):
    """(int c_k, int c_k over c_k >= threshold, and that part's centre
    int c_k x / int c_k) over the mesh, Gauss on the Q1 elements, as
    src/model/cells.c observes a cell (division.observe_threshold)."""
    dim = fields.dim
    x = fields.coords[fields.elements]            # e x nen x dim
    c = fields.c(k)[fields.elements]              # e x nen
    g = 1 / np.sqrt(3)
    if dim == 2:
        ref = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float)
    else:
        ref = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                        [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
    pts = np.array(np.meshgrid(*([[-g, g]] * dim), indexing="ij")).reshape(dim, -1).T
    mass, core, moment = 0.0, 0.0, np.zeros(dim)
    for q in pts:
        n = np.prod(1 + ref * q, axis=1) / 2 ** dim                  # nen
        dn = np.empty((len(ref), dim))                               # dN/dxi
        for d in range(dim):
            other = np.prod(np.delete(1 + ref * q, d, axis=1), axis=1)
            dn[:, d] = ref[:, d] * other / 2 ** dim
        jac = np.einsum("ean,ad->end", x, dn)                        # e x dim x dim
        w = np.abs(np.linalg.det(jac))
        cq = c @ n
        mass += np.sum(w * cq)
        cw = np.where(cq >= threshold, cq, 0.0)
        core += np.sum(w * cw)
        moment += np.einsum("e,e,ed->d", w, cw, np.einsum("ead,a->ed", x, n))
    return mass, core, moment / core


def cells_at(table, step):
    rows = np.asarray(table["step"]) == step
    return {name: np.asarray(table[name], dtype=float)[rows]
            for name in ("mass", "core_mass", "xc", "yc")}


def test_vtu_fields_2d(small, tmp_path):
    r = softpack.run(small, out=tmp_path / "o")
    steps = r.field_steps
    assert steps == [0, 2, 4, 6]
    for step in (0, steps[-1]):
        f = r.fields(step)
        assert f.step == step and f.dim == 2 and f.n_cells == 2
        assert f.coords.shape == (len(f.points), 2) and f.elements.shape[1] == 4
        want = cells_at(r.cells, step)
        for k in (1, 2):
            mass, core, centre = gauss_integrals(f, k)
            assert mass == pytest.approx(want["mass"][k - 1], rel=1e-10)
            assert core == pytest.approx(want["core_mass"][k - 1], rel=1e-10)
            assert centre[0] == pytest.approx(want["xc"][k - 1], rel=1e-8, abs=1e-12)
            assert centre[1] == pytest.approx(want["yc"][k - 1], rel=1e-8, abs=1e-12)
        # cell_id: the cell whose c > 1/2 is largest
        cs = np.stack([f.c(1), f.c(2)])
        expect = np.where(cs.max(axis=0) > 0.5, cs.argmax(axis=0) + 1, 0)
        assert np.array_equal(f.point_data["cell_id"], expect)


def test_vtu_fields_3d(source_dir, tmp_path):
    seen = []
    r = softpack.run(f"{source_dir}/tests/scenes/sphere_3d.yaml", out=tmp_path / "o",
                     overrides={"time.max_steps": 2, "mesh.nx": 8, "mesh.ny": 8, "mesh.nz": 8},
                     on_step=seen.append)
    s = seen[-1]
    assert s.dim == 3 and s.centres.shape == (1, 3) and s.moments.shape == (1, 3)
    assert np.allclose(s.axes[0] @ s.axes[0].T, np.eye(3), atol=1e-9)   # orthonormal
    assert np.allclose(s.inertia[0] @ s.axes[0].T, s.axes[0].T * s.moments[0], atol=1e-12)
    assert np.array_equal(s.long_axes[0], s.axes[0, 2])
    zc = np.asarray(r.cells["zc"], float)[np.asarray(r.cells["step"]) == s.step]
    assert s.centres[0, 2] == pytest.approx(zc[0], rel=1e-12)
    f = r.fields()
    assert f.dim == 3 and f.elements.shape[1] == 8 and f.coords.shape[1] == 3
    mass, core, centre = gauss_integrals(f, 1)
    want = cells_at(r.cells, f.step)
    assert mass == pytest.approx(want["mass"][0], rel=1e-10)
    assert core == pytest.approx(want["core_mass"][0], rel=1e-10)
    assert centre[:2] == pytest.approx([want["xc"][0], want["yc"][0]], rel=1e-8)


def test_step_fields_equal_vtu(small, tmp_path):
    got = {}

    def grab(s):
        if s.step in (2, 4):
            got[s.step] = (s.mesh(), [s.field(k) for k in range(s.n_cells)])

    r = softpack.run(small, out=tmp_path / "o", on_step=grab)
    for step, ((coords, elements), cs) in got.items():
        f = r.fields(step)
        assert np.array_equal(coords, f.coords)
        assert np.array_equal(elements, f.elements)
        for k, c in enumerate(cs):
            assert np.array_equal(c, f.c(k + 1))


def test_step_fields_after_callback(small, tmp_path):
    kept = []
    softpack.run(small, out=tmp_path / "o", overrides={"time.max_steps": 1},
                 on_step=kept.append)
    with pytest.raises((RuntimeError, NotImplementedError)):
        kept[0].field(0)
