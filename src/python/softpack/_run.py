"""softpack.run: a scene run by libsoftpack (sp_run_text / sp_run_file_restart),
its steps seen from Python, its outputs read back."""

import ctypes
import os
import re
import tempfile

import numpy as np

from . import _capi, _mpi, _outputs, _scene


# --------------------------------------------------------------------------
# Errors
# --------------------------------------------------------------------------

class SoftpackError(RuntimeError):
    """A run failed: ``code`` (sp_error_code, error.h), ``kind`` (its class
    in words: "bad input", "solver", "output", "memory", "MPI",
    "internal") and ``message`` (sp_error_message()).  ``result``: the
    RunResult of what the run wrote (a solver failure writes its last good
    state), or None."""

    def __init__(self, code, kind, message, result=None):
        super().__init__(message)
        self.code, self.kind, self.message, self.result = code, kind, message, result


class SceneError(SoftpackError, ValueError):
    """A bad scene or override (SP_ERR_INPUT, the command's exit status 2):
    nothing was written.  ``key``: the scene key the message names
    ("time.t_end", "cells[2].radius", or a section, "bogus"), None if it
    names none."""

    def __init__(self, code, kind, message, key):
        super().__init__(code, kind, message)
        self.key = key


class SolverError(SoftpackError):
    """SP_ERR_SOLVER: a step failed beyond its retries (the last good state
    is written: ``result``)."""


_SECTIONS = ("mesh", "model", "time", "noise", "solver", "output", "division", "source",
             "layout", "shape", "initial", "cells", "lineage")
_KEY = re.compile(r"(?<![\w./-])([a-z][a-z0-9_]*(?:\[\d+\])?(?:\.[a-z][a-z0-9_]*)?)(?=[:\s,;=]|$)")


def key_of_message(message):
    """The scene key a library message names: the first "section.key",
    "section[i].key" or bare section name of softpack's scene in it."""
    for m in _KEY.finditer(message):
        word = m.group(1)
        section = re.split(r"[.\[]", word)[0]
        if section in _SECTIONS and ("." in word or "[" in word):
            return word
    m = re.search(r"(?<![\w./-])([A-Za-z_][\w]*(?:\[\d+\])?\.[A-Za-z_]\w*): unknown", message)
    if m:
        return m.group(1)
    m = re.search(r"(?<![\w./-])([A-Za-z_]\w*): unknown section", message)
    if m:
        return m.group(1)
    for m in _KEY.finditer(message):
        if m.group(1) in _SECTIONS:
            return m.group(1)
    return None


# --------------------------------------------------------------------------
# What a step callback sees
# --------------------------------------------------------------------------

class StepInfo:
    """An accepted step as a callback sees it (sp_step_info): ``step``,
    ``t``, ``dt``, ``t_end``, ``n_cells``, ``newton_its``,
    ``failed_attempts``, ``attempts`` (a list of dicts), ``error_estimate``,
    ``wall_seconds``, ``last``, ``dim``; the cells' observables as numpy
    arrays, one row per cell (cell k of the CSVs is row k - 1):
    ``masses``, ``mass_cores``, ``centres`` (n x dim), ``inertia`` (n x
    dim x dim), ``moments`` (n x dim, descending), ``axes`` (n x dim x dim:
    axes[k, i] the unit eigenvector of moments[k, i]), ``long_axes`` (n x
    dim, axes[:, dim - 1]), ``volumes`` (area in
    2D), ``names`` (a list; "" for an unnamed cell).  With API 0.2,
    ``mesh()`` and ``field(k)`` give the mesh and cell k's c (0-based k)
    during the callback."""

    __slots__ = ("_lib", "_ptr", "_obs", "step", "t", "dt", "t_end", "n_cells", "newton_its",
                 "failed_attempts", "error_estimate", "wall_seconds", "last", "dim", "_names",
                 "_attempts", "_live")

    def __init__(self, lib, ptr):
        s = ptr.contents
        self._lib, self._ptr, self._live = lib, ptr, True
        self.step, self.t, self.dt, self.t_end = s.step, s.t, s.dt, s.t_end
        self.n_cells, self.newton_its = s.n_cells, s.newton_its
        self.failed_attempts, self.error_estimate = s.failed_attempts, s.error_estimate
        self.wall_seconds, self.last = s.wall_seconds, bool(s.last)
        n = s.n_cells
        size = ctypes.sizeof(lib.CellObs)
        buf = ctypes.string_at(s.cells, n * size) if n else b""
        self._obs = np.frombuffer(buf, dtype=lib.obs_dtype, count=n)
        self.dim = s.dim
        self._names = [s.names[k].value.decode() for k in range(n)] if s.names else [""] * n
        self._attempts = None
        if s.failed_attempts:
            self._attempts = []
            for a in s.attempts[:s.failed_attempts]:
                self._attempts.append({
                    "dt": a.dt, "why": a.why, "newton": a.newton, "newton_its": a.newton_its,
                    "factorisations": a.factorisations,
                    "residual_norms": list(a.residual_norms[:a.n_residuals]),
                    "error_estimate": a.error_estimate, "dt_next": a.dt_next})

    def _close(self):
        self._live = False
        self._ptr = None

    @property
    def attempts(self):
        return self._attempts or []

    @property
    def names(self):
        return list(self._names)

    @property
    def masses(self):
        return self._obs["mass"].copy()

    @property
    def mass_cores(self):
        return self._obs["mass_core"].copy()

    @property
    def centres(self):
        return self._obs["centre"][:, :self.dim].copy()

    @property
    def moments(self):
        return self._obs["moments"][:, :self.dim].copy()

    @property
    def axes(self):
        return self._obs["axes"][:, :self.dim, :self.dim].copy()

    @property
    def long_axes(self):
        """n x dim: each cell's long axis (the smallest moment's eigenvector;
        a division's cut is normal to it)."""
        return self.axes[:, self.dim - 1, :].copy()

    @property
    def inertia(self):
        return self._obs["inertia"][:, :self.dim, :self.dim].copy()

    @property
    def volumes(self):
        return self._obs["volume"].copy()

    def _need_live(self, what):
        if not self._live:
            raise RuntimeError(f"StepInfo.{what}: only during the callback that got it")

    def mesh(self):
        """(coords n_nodes x dim, elements n_elements x nodes per element,
        0-based) of the run's mesh (copies)."""
        self._need_live("mesh()")
        dim, nn, ne, npe, xy, el = self._mesh()
        coords = np.ctypeslib.as_array(xy, shape=(nn, dim)).copy()
        elements = np.ctypeslib.as_array(el, shape=(ne, npe)).astype(np.int64)
        return coords, elements

    def _mesh(self):
        dim, nn, ne, npe = ctypes.c_int(), ctypes.c_int(), ctypes.c_int(), ctypes.c_int()
        xy = ctypes.POINTER(ctypes.c_double)()
        el = ctypes.POINTER(ctypes.c_int)()
        rc = self._lib.lib.sp_step_mesh(self._ptr, ctypes.byref(dim), ctypes.byref(nn),
                                        ctypes.byref(xy), ctypes.byref(ne), ctypes.byref(npe),
                                        ctypes.byref(el))
        _check(self._lib, rc)
        return dim.value, nn.value, ne.value, npe.value, xy, el

    def field(self, cell):
        """Cell @p cell's c on the mesh's nodes (0 off its support);
        @p cell 0-based (row of the observables)."""
        self._need_live("field()")
        if not 0 <= cell < self.n_cells:
            raise IndexError(f"cell {cell}: the step has {self.n_cells} cells (0-based)")
        nn = self._mesh()[1]
        c = np.zeros(nn)
        _check(self._lib, self._lib.lib.sp_step_cell_field(
            self._ptr, cell, c.ctypes.data_as(ctypes.POINTER(ctypes.c_double))))
        return c

    def __repr__(self):
        return (f"<softpack.StepInfo step {self.step} t={self.t:g} dt={self.dt:g} "
                f"{self.n_cells} cells>")


# --------------------------------------------------------------------------
# What a run did
# --------------------------------------------------------------------------

class RunResult:
    """A finished run: ``summary`` (sp_run_summary as a dict), its main
    entries as attributes (``steps``, ``failed_attempts``, ``newton_its``,
    ``factorisations``, ``wall_seconds``, ``t_final``, ``divisions``,
    ``n_cells``), ``stopped`` / ``why`` (why it stopped: "t_end",
    "max_steps", "callback", "exception", "signal"; "error" in a
    SolverError's result), ``out`` (its
    directory) and its outputs read from there on first use: ``energy``,
    ``cells``, ``divisions_table``, ``contacts`` (DataFrames with pandas,
    else numpy structured arrays), ``field_steps`` and ``fields(step)``."""

    def __init__(self, summary, out, why, t_end=None):
        self.summary = {name: getattr(summary, name) for name, _ in summary._fields_}
        self.out = out
        self.why = why
        self.t_end = t_end
        self._tables = {}

    def __getattr__(self, name):
        s = self.__dict__.get("summary")
        if s is not None and name in s:
            return s[name]
        raise AttributeError(name)

    def _table(self, name):
        if name not in self._tables:
            path = os.path.join(self.out, f"{name}.csv")
            if not os.path.exists(path):
                raise FileNotFoundError(f"{path}: not written by this run")
            self._tables[name] = _outputs.read_csv(path)
        return self._tables[name]

    @property
    def energy(self):
        return self._table("energy")

    @property
    def cells(self):
        return self._table("cells")

    @property
    def divisions_table(self):
        return self._table("divisions")

    @property
    def contacts(self):
        return self._table("contacts")

    @property
    def field_steps(self):
        return list(_outputs.field_files(self.out))

    def fields(self, step=None):
        """The Fields of the output at @p step (None: the last one)."""
        files = _outputs.field_files(self.out)
        if not files:
            raise FileNotFoundError(f"{self.out}: no fields_*.vtu")
        if step is None:
            step = max(files)
        if step not in files:
            raise KeyError(f"step {step}: fields written at steps {list(files)}")
        return _outputs.read_vtu(files[step])

    def __repr__(self):
        return (f"<softpack.RunResult {self.steps} steps to t={self.t_final:g} ({self.why}), "
                f"{self.n_cells} cells, {self.wall_seconds:.3g} s, out={self.out!r}>")


def _check(lib, rc, result=None):
    if rc == _capi.SP_OK:
        return
    message = lib.error_message()
    kind = lib.lib.sp_error_class_name(rc).decode()
    if rc == _capi.SP_ERR_INPUT:
        raise SceneError(rc, kind, message, key_of_message(message))
    if rc == _capi.SP_ERR_SOLVER:
        raise SolverError(rc, kind, message, result)
    raise SoftpackError(rc, kind, message, result)


# --------------------------------------------------------------------------
# run()
# --------------------------------------------------------------------------

def _scene_input(scene):
    """("file", path) or ("text", yaml_text, dict_or_None)."""
    if isinstance(scene, dict):
        return "dict", scene
    if isinstance(scene, os.PathLike):
        return "file", os.fspath(scene)
    if isinstance(scene, bytes):
        scene = scene.decode()
    if isinstance(scene, str):
        if "\n" not in scene and os.path.isfile(scene):
            return "file", scene
        if "\n" in scene or ":" in scene or "{" in scene:
            return "text", scene
        raise FileNotFoundError(f"scene '{scene}': no such file (and not YAML text)")
    raise TypeError(f"scene: expected a dict, a YAML string or a path, not {type(scene).__name__}")


def _has_labels(scene):
    ini = scene.get("initial") if isinstance(scene, dict) else None
    return isinstance(ini, dict) and "labels" in ini


def scene_text(scene, label_dir=None):
    """The YAML text softpack.run gives the library for the dict @p scene
    (a label array written into @p label_dir)."""
    if _has_labels(scene):
        if label_dir is None:
            raise ValueError("scene_text: initial.labels needs a directory for its file")
        scene = dict(scene)
        scene["initial"] = _scene.materialise_labels(scene["initial"], label_dir)
    return _scene.dump(scene)


def _default_out(kind, value):
    if kind == "file":
        return os.path.join("out", os.path.splitext(os.path.basename(value))[0])
    return os.path.join("out", "scene")


def run(scene, out=None, overrides=None, on_step=None, comm=None, name=None, restart=None):
    """Run @p scene with libsoftpack and return a RunResult.

    scene: a dict (the YAML file's structure), a YAML string or a path.
    out: the output directory (None: out/<file's name> for a file,
        out/scene otherwise, as the command).
    overrides: {"section.key": value} or ["section.key=value", ...] (the
        command's --set).
    on_step: f(StepInfo) called after every accepted step; a true return
        stops the run (its state written as at the end; why = "callback");
        an exception stops it the same way and is raised again here once
        the run has returned (why = "exception").
    comm: an mpi4py communicator (None: MPI_COMM_WORLD, one process
        without mpiexec).  Every rank of it calls run() alike.
    name: the scene's name in messages for a dict or text; relative file
        names in it are taken from its directory (None: "scene", i.e. from
        the working directory).
    restart: a checkpoint file to continue from (a scene file only).

    Raises SceneError (a bad key or value: ``.key``, ``.message``; nothing
    written), SolverError, SoftpackError."""
    global _running
    if _running:
        raise RuntimeError("softpack.run: a run is in progress in this process (called from "
                           "on_step?): the library runs one scene at a time")
    lib = _capi.library()
    _mpi.ensure_initialised(want_mpi4py=comm is not None)
    handle = _mpi.comm_handle(comm)
    kind, value = _scene_input(scene)
    if restart is not None and kind != "file":
        raise ValueError("restart: only with a scene file")
    out = os.fspath(out) if out is not None else _default_out(kind, value)
    sets = [s.encode() for s in _scene.overrides_list(overrides)]
    c_sets = (ctypes.c_char_p * max(1, len(sets)))(*sets)
    summary = _capi.RunSummary()
    state = {"exc": None, "t_end": None, "stopped_by": None}

    def trampoline(ptr, _user):
        info = None
        try:
            if on_step is None:
                state["t_end"] = ptr.contents.t_end
                return 0
            info = StepInfo(lib, ptr)
            state["t_end"] = info.t_end
            stop = on_step(info)
            if stop:
                state["stopped_by"] = "callback"
            return 1 if stop else 0
        except BaseException as e:  # noqa: B036 (KeyboardInterrupt too: stop cleanly)
            state["exc"] = e
            return 1
        finally:
            if info is not None:
                info._close()

    callback = lib.Callback(trampoline)
    _running = True
    try:
        rc = _run_c(lib, kind, value, name, sets, c_sets, out, restart, handle, callback, summary)
    finally:
        _running = False
    why = _why(summary, state) if rc == _capi.SP_OK else "error"
    result = RunResult(summary, out, why, state["t_end"])
    _check(lib, rc, result)
    if state["exc"] is not None:
        e = state["exc"]
        try:
            e.softpack_result = result
        except AttributeError:
            pass
        raise e
    return result


_running = False


def request_stop():
    """Ask the run in progress to write a checkpoint at the end of its step
    and stop there (why = "signal"): sp_run_request_stop, safe from a signal
    handler or another thread."""
    _capi.library().lib.sp_run_request_stop()


def _run_c(lib, kind, value, name, sets, c_sets, out, restart, handle, callback, summary):
    with tempfile.TemporaryDirectory(prefix="softpack-labels-") as tmp:
        if kind == "dict":
            text = scene_text(value, tmp)
            kind = "text"
        else:
            text = value
        lib.lib.sp_error_clear()
        if kind == "text":
            data = text.encode()
            rc = lib.lib.sp_run_text((name or "scene").encode(), data, len(data), len(sets),
                                     c_sets, out.encode(), handle, callback, None,
                                     ctypes.byref(summary))
        else:
            rs = None
            if restart is not None:
                rs = _capi.Restart(os.fspath(restart).encode(), None, 0)
            rc = lib.lib.sp_run_file_restart(text.encode(), len(sets), c_sets, out.encode(),
                                             ctypes.byref(rs) if rs else None, handle,
                                             callback, None, ctypes.byref(summary))
    return rc


def _why(summary, state):
    if state["exc"] is not None:
        return "exception"
    if summary.stopped == _capi.SP_STOPPED_CALLBACK:
        return "callback"
    if summary.stopped == _capi.SP_STOPPED_SIGNAL:
        return "signal"
    t_end = state["t_end"]
    if t_end is not None and summary.t_final >= t_end * (1 - 1e-12):
        return "t_end"
    return "max_steps" if t_end is not None else "t_end"
