"""softpack.run on a dict scene: its DataFrames are the files, on_step sees
every step and stops a run, a bad key raises with the key and writes
nothing, an exception in on_step stops the run with its state written."""
import math
import os

import numpy as np
import pytest

import softpack
from conftest import csv_rows


def columns(table):
    return list(table.columns) if hasattr(table, "columns") else list(table.dtype.names)


def column(table, name):
    return np.asarray(table[name], dtype=float)


def test_version():
    assert softpack.__version__ == softpack.library_version()
    assert softpack.__version__.count(".") >= 1


def test_dict_scene_tables_match_files(small, tmp_path):
    out = tmp_path / "run"
    r = softpack.run(small, out=out)
    assert r.steps == 6 and r.why == "max_steps" and r.n_cells == 2
    assert r.failed_attempts >= 0 and r.factorisations > 0 and r.wall_seconds > 0
    assert os.path.samefile(r.out, out)
    for name, table in (("energy", r.energy), ("cells", r.cells), ("contacts", r.contacts),
                        ("divisions", r.divisions_table)):
        header, rows = csv_rows(out / f"{name}.csv")
        assert columns(table) == header, name
        assert len(table) == len(rows), name
        for j, col in enumerate(header):
            want = np.array([row[j] if row[j] is not None else np.nan for row in rows])
            got = column(table, col)
            assert np.array_equal(got, want, equal_nan=True), (name, col)
    # one energy row per step (and step 0), cells and contacts per output
    assert list(column(r.energy, "step")) == list(range(7))
    assert set(column(r.cells, "cell")) == {1, 2}


def test_yaml_text_and_file_scenes(small, tmp_path):
    a = softpack.run(small, out=tmp_path / "dict")
    text = softpack.scene_text(small)
    b = softpack.run(text, out=tmp_path / "text")
    path = tmp_path / "scene.yaml"
    path.write_text(text)
    c = softpack.run(str(path), out=tmp_path / "file")
    d = softpack.run(path, out=tmp_path / "pathlib",
                     overrides=["time.max_steps=4", ("output.every", 1)])
    for other in (b, c):
        assert np.array_equal(column(a.cells, "mass"), column(other.cells, "mass"))
    assert d.steps == 4 and len(d.cells) == 2 * 5


def test_on_step_sees_every_step(small, tmp_path):
    seen = []

    def watch(s):
        assert s.masses.shape == (2,) and s.centres.shape == (2, 2)
        assert s.moments.shape == (2, 2) and s.axes.shape == (2, 2, 2)
        assert s.inertia.shape == (2, 2, 2) and s.volumes.shape == (2,)
        assert len(s.names) == 2 and s.dim == 2
        assert np.all(s.moments[:, 0] >= s.moments[:, 1])
        # axes[k, i]: a unit eigenvector of the inertia tensor for moments[k, i]
        for k in range(2):
            for i in range(2):
                v = s.axes[k, i]
                assert abs(np.linalg.norm(v) - 1) < 1e-9
                assert np.allclose(s.inertia[k] @ v, s.moments[k, i] * v, atol=1e-12)
        seen.append((s.step, s.t, s.dt, s.masses, s.centres, s.moments))

    r = softpack.run(small, out=tmp_path / "o", overrides={"output.every": 1}, on_step=watch)
    assert [x[0] for x in seen] == list(range(1, r.steps + 1))
    cells = r.cells
    for step, t, dt, masses, centres, moments in seen:
        rows = np.asarray(cells["step"]) == step
        assert np.allclose(column(cells, "mass")[rows], masses, rtol=1e-14, atol=0)
        assert np.allclose(column(cells, "xc")[rows], centres[:, 0], rtol=1e-12, atol=1e-15)
        assert np.allclose(column(cells, "yc")[rows], centres[:, 1], rtol=1e-12, atol=1e-15)
        assert np.allclose(column(cells, "I1")[rows], moments[:, 0], rtol=1e-12)
        e = np.asarray(r.energy["step"]) == step
        assert column(r.energy, "t")[e][0] == t and column(r.energy, "dt")[e][0] == dt


def test_on_step_stops_the_run(small, tmp_path):
    seen = []
    r = softpack.run(small, out=tmp_path / "o", on_step=lambda s: seen.append(s.step) or s.step == 3)
    assert seen == [1, 2, 3]
    assert r.steps == 3 and r.stopped == 1 and r.why == "callback"
    assert list(column(r.energy, "step")) == [0, 1, 2, 3]
    assert 3 in r.field_steps                    # the state written as at the end


@pytest.mark.parametrize("bad, key", [
    ({"time.t_ed": 1}, "time.t_ed"),
    ({"time.dt": -1}, "time.dt"),
    ({"bogus.key": 1}, "bogus.key"),
])
def test_bad_override_raises_with_key(small, tmp_path, bad, key):
    out = tmp_path / "never"
    with pytest.raises(softpack.SceneError) as e:
        softpack.run(small, out=out, overrides=bad)
    assert e.value.key == key, e.value.message
    assert key in str(e.value) and e.value.code == 2 and e.value.kind == "bad input"
    assert not out.exists()


def test_bad_scene_key_raises_with_key(small, tmp_path):
    small["time"]["t_ed"] = 0.1
    out = tmp_path / "never"
    with pytest.raises(softpack.SceneError) as e:
        softpack.run(small, out=out)
    assert e.value.key == "time.t_ed" and "unknown key" in e.value.message
    small["time"].pop("t_ed")
    small["cells"][1]["radius"] = -1
    with pytest.raises(softpack.SceneError) as e:
        softpack.run(small, out=out)
    assert e.value.key == "cells[1].radius"
    assert not out.exists()


class Boom(Exception):
    pass


def test_exception_in_on_step_stops_cleanly(small, tmp_path):
    out = tmp_path / "o"

    def explode(s):
        if s.step == 2:
            raise Boom("at step 2")

    with pytest.raises(Boom, match="at step 2") as e:
        softpack.run(small, out=out, on_step=explode)
    r = e.value.softpack_result
    assert r.steps == 2 and r.why == "exception"
    # the run's state written as at the end: logs to step 2, its fields
    assert list(column(r.energy, "step")) == [0, 1, 2]
    assert r.field_steps[-1] == 2
    f = r.fields()
    assert f.step == 2 and math.isclose(f.time, column(r.energy, "t")[-1], rel_tol=1e-14)
    # and the library is usable again afterwards
    assert softpack.run(small, out=tmp_path / "again", overrides={"time.max_steps": 1}).steps == 1


def test_key_of_message():
    k = softpack.key_of_message
    assert k("scene: time.bogus: unknown key; time has control, scheme") == "time.bogus"
    assert k("--set bogus.key=1: bogus.key: unknown section; the sections are mesh") == "bogus.key"
    assert k("scene: cells[0].radius: expected a number > 0, got -1") == "cells[0].radius"
    assert k("scene.yaml: mesh.refinements: expected an integer") == "mesh.refinements"


def test_tables_without_pandas(small, tmp_path, monkeypatch):
    """numpy alone: the tables are structured arrays with the same values."""
    r = softpack.run(small, out=tmp_path / "o")
    monkeypatch.setattr(softpack._outputs, "pandas", None)
    for name in ("energy", "cells", "contacts", "divisions"):
        table = getattr(r, "divisions_table" if name == "divisions" else name)
        assert isinstance(table, np.ndarray)
        header, rows = csv_rows(tmp_path / "o" / f"{name}.csv")
        assert list(table.dtype.names) == header and len(table) == len(rows)
        for j, col in enumerate(header):
            want = np.array([row[j] if row[j] is not None else np.nan for row in rows])
            assert np.array_equal(column(table, col), want, equal_nan=True), (name, col)


def test_scene_without_yaml(small, monkeypatch, tmp_path):
    """Without PyYAML a dict is written as JSON (YAML too) and runs alike;
    out=None: out/scene, as the command."""
    monkeypatch.setattr(softpack._scene, "yaml", None)
    monkeypatch.chdir(tmp_path)
    text = softpack.scene_text(small)
    assert text.lstrip().startswith("{")
    r = softpack.run(text, out=None, overrides={"time.max_steps": 1}, name="scene")
    assert r.steps == 1 and (tmp_path / "out" / "scene" / "energy.csv").exists()


def test_request_stop_and_no_nested_runs(small, tmp_path):
    """softpack.request_stop() (sp_run_request_stop: a signal handler's
    call) stops the run with a checkpoint; a run inside on_step is refused."""
    nested = []

    def watch(s):
        if s.step == 1:
            try:
                softpack.run(small, out=tmp_path / "nested")
            except RuntimeError as e:
                nested.append(str(e))
        if s.step == 2:
            softpack.request_stop()

    r = softpack.run(small, out=tmp_path / "o", on_step=watch)
    assert r.why == "signal" and r.steps <= 3 and r.checkpoints >= 1
    assert nested and "in progress" in nested[0] and not (tmp_path / "nested").exists()


def test_names(small, tmp_path):
    """The cells' names (cells[i].name) in StepInfo.names (API 0.2) and in
    the fields' cell_name."""
    small["cells"][0]["name"] = "AB"
    small["cells"][1]["name"] = "P1"
    seen = []
    r = softpack.run(small, out=tmp_path / "o", overrides={"time.max_steps": 2},
                     on_step=lambda s: seen.append(s.names))
    assert r.fields().names == ["AB", "P1"]
    assert seen == [["AB", "P1"]] * 2


def test_solver_failure_raises_with_state(small, tmp_path):
    """A step that fails beyond its retries: SolverError (exit status 1's
    class), its message, and the result of what was written."""
    with pytest.raises(softpack.SolverError) as e:
        softpack.run(small, out=tmp_path / "o",
                     overrides={"solver.newton_max_its": 1, "time.max_retries": 1,
                                "time.control": "fixed", "time.dt": 0.01})
    assert e.value.code == 1 and e.value.kind == "solver"
    assert "time.max_retries" in e.value.message
    r = e.value.result
    assert r.why == "error" and r.steps == 0
    assert list(column(r.energy, "step")) == [0]
