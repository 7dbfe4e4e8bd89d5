"""ctypes declarations of libsoftpack's public C API (src/public/*.h).

Everything that depends on the C layout is in this module: the structures
of run_types.h and cell_obs.h, the functions of run.h and error.h, and how
the library is found.  The layouts are those of API 0.2 (API below); a
library of another version (sp_version()) is refused when loaded.

The library is looked for, in order (the first that exists wins):

1. next to an installed tree: the path from this package's directory to
   the install's lib directory, written by ``cmake --install`` into
   ``_install.py``;
2. ``$SOFTPACK_LIBRARY`` (a path to libsoftpack.so);
3. ``ctypes.util.find_library("softpack")`` (ldconfig's cache, e.g. the
   .deb installed in /usr);
4. the build tree: ``_build.py``, written by CMake into
   ``build/python/softpack/`` with the library's absolute path.
"""

import ctypes
import ctypes.util
import os
import re

import numpy as np

API = (0, 2)  # the MAJOR.MINOR of libsoftpack whose headers this module mirrors
SP_MAX_NEWTON_HISTORY = 64
SP_CELL_NAME_MAX = 32

# error.h
SP_OK, SP_ERR_SOLVER, SP_ERR_INPUT, SP_ERR_IO, SP_ERR_MEMORY, SP_ERR_INTERNAL, SP_ERR_MPI = range(7)
# run_types.h
SP_STOPPED_CALLBACK, SP_STOPPED_SIGNAL = 1, 2


class Attempt(ctypes.Structure):
    """sp_attempt (run_types.h): a failed attempt at a step."""
    _fields_ = [("dt", ctypes.c_double),
                ("why", ctypes.c_int),
                ("newton", ctypes.c_int),
                ("newton_its", ctypes.c_int),
                ("factorisations", ctypes.c_int),
                ("n_residuals", ctypes.c_int),
                ("residual_norms", ctypes.c_double * SP_MAX_NEWTON_HISTORY),
                ("error_estimate", ctypes.c_double),
                ("dt_next", ctypes.c_double)]


class CellObs(ctypes.Structure):
    """sp_cell_obs (cell_obs.h)."""
    _fields_ = [("mass", ctypes.c_double),
                ("mass_core", ctypes.c_double),
                ("centre", ctypes.c_double * 3),
                ("inertia", (ctypes.c_double * 3) * 3),
                ("moments", ctypes.c_double * 3),
                ("axes", (ctypes.c_double * 3) * 3),
                ("long_axis", ctypes.c_int),
                ("volume", ctypes.c_double)]


class RunSummary(ctypes.Structure):
    """sp_run_summary (run_types.h)."""
    _fields_ = [("steps", ctypes.c_int),
                ("failed_attempts", ctypes.c_int),
                ("newton_its", ctypes.c_long),
                ("factorisations", ctypes.c_long),
                ("failed_factorisations", ctypes.c_long),
                ("linear_its", ctypes.c_long),
                ("t_final", ctypes.c_double),
                ("dt_smallest", ctypes.c_double),
                ("wall_seconds", ctypes.c_double),
                ("t_assembly", ctypes.c_double),
                ("t_factor", ctypes.c_double),
                ("t_solve", ctypes.c_double),
                ("divisions", ctypes.c_int),
                ("n_cells", ctypes.c_int),
                ("layout_changes", ctypes.c_int),
                ("support_mass_correction", ctypes.c_double),
                ("t_layout", ctypes.c_double),
                ("support_mass_dropped", ctypes.c_double),
                ("support_energy_rise", ctypes.c_double),
                ("unknowns_max", ctypes.c_long),
                ("checkpoints", ctypes.c_int),
                ("t_checkpoints", ctypes.c_double),
                ("stopped", ctypes.c_int),
                ("mb_mesh", ctypes.c_double),
                ("mb_state", ctypes.c_double),
                ("mb_matrix", ctypes.c_double),
                ("mb_solver", ctypes.c_double),
                ("mb_sent_per_newton", ctypes.c_double)]


class StepInfo(ctypes.Structure):
    """sp_step_info (run_types.h)."""
    _fields_ = [("step", ctypes.c_int),
                ("t", ctypes.c_double),
                ("dt", ctypes.c_double),
                ("t_end", ctypes.c_double),
                ("n_cells", ctypes.c_int),
                ("newton_its", ctypes.c_int),
                ("failed_attempts", ctypes.c_int),
                ("attempts", ctypes.POINTER(Attempt)),
                ("error_estimate", ctypes.c_double),
                ("cells", ctypes.POINTER(CellObs)),
                ("wall_seconds", ctypes.c_double),
                ("last", ctypes.c_int),
                ("dim", ctypes.c_int),
                ("names", ctypes.POINTER(ctypes.c_char * SP_CELL_NAME_MAX)),
                ("run", ctypes.c_void_p)]


class Restart(ctypes.Structure):
    """sp_restart (run.h)."""
    _fields_ = [("checkpoint", ctypes.c_char_p),
                ("resume_dir", ctypes.c_char_p),
                ("as_initial", ctypes.c_int)]


def _package_dir():
    return os.path.dirname(os.path.abspath(__file__))


def _installed_library():
    """libsoftpack of the install this package belongs to (_install.py)."""
    try:
        from . import _install  # written by cmake --install
    except ImportError:
        return None
    libdir = os.path.normpath(os.path.join(_package_dir(), _install.LIBDIR_FROM_PACKAGE))
    for name in (_install.SONAME, "libsoftpack.so"):
        path = os.path.join(libdir, name)
        if os.path.exists(path):
            return path
    return None


def _build_tree_library():
    try:
        from . import _build  # written by CMake into build/python/softpack/
    except ImportError:
        return None
    return _build.LIBRARY if os.path.exists(_build.LIBRARY) else None


def library_path():
    """The libsoftpack the package loads (see the module's docstring)."""
    path = _installed_library()
    if path:
        return path
    env = os.environ.get("SOFTPACK_LIBRARY")
    if env:
        if not os.path.exists(env):
            raise OSError(f"SOFTPACK_LIBRARY={env}: no such file")
        return env
    found = ctypes.util.find_library("softpack")
    if found:
        return found
    path = _build_tree_library()
    if path:
        return path
    raise OSError("libsoftpack not found: install softpack (cmake --install or the .deb), "
                  "or set SOFTPACK_LIBRARY to build/libsoftpack.so (docs/python.md)")


class Library:
    """The loaded library, its API version and its typed functions."""

    def __init__(self, path=None):
        self.path = path or library_path()
        # Open MPI opens its plugins with dlopen: they need libmpi's symbols
        # global, so libmpi (a dependency of libsoftpack) is loaded first
        # with RTLD_GLOBAL, as mpi4py does.
        self.mpi = _load_libmpi()
        self.lib = ctypes.CDLL(self.path, mode=ctypes.RTLD_GLOBAL)
        lib = self.lib
        self.version = self._version()
        self.api = tuple(int(x) for x in self.version.split(".")[:2])
        if self.api != API:
            raise OSError(f"{self.path} is libsoftpack {self.version}; this package binds "
                          f"{API[0]}.{API[1]} (install the two together: docs/python.md)")
        self.CellObs, self.StepInfo = CellObs, StepInfo
        self.obs_dtype = np.dtype(self.CellObs)
        self.Callback = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(self.StepInfo),
                                         ctypes.c_void_p)
        comm = ctypes.c_void_p
        strings = ctypes.POINTER(ctypes.c_char_p)
        lib.sp_run_text.restype = ctypes.c_int
        lib.sp_run_text.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_size_t,
                                    ctypes.c_int, strings, ctypes.c_char_p, comm,
                                    self.Callback, ctypes.c_void_p,
                                    ctypes.POINTER(RunSummary)]
        lib.sp_run_file_restart.restype = ctypes.c_int
        lib.sp_run_file_restart.argtypes = [ctypes.c_char_p, ctypes.c_int, strings,
                                            ctypes.c_char_p, ctypes.POINTER(Restart), comm,
                                            self.Callback, ctypes.c_void_p,
                                            ctypes.POINTER(RunSummary)]
        lib.sp_error_message.restype = ctypes.c_char_p
        lib.sp_error_message.argtypes = []
        lib.sp_error_clear.restype = None
        lib.sp_error_class_name.restype = ctypes.c_char_p
        lib.sp_error_class_name.argtypes = [ctypes.c_int]
        lib.sp_run_request_stop.restype = None
        lib.sp_step_mesh.restype = ctypes.c_int
        # int sp_step_mesh(const sp_step_info *, int *dim, int *n_nodes,
        #     const double **coords, int *n_elements, int *nodes_per_element,
        #     const int **elements)
        lib.sp_step_mesh.argtypes = [
            ctypes.POINTER(self.StepInfo), ctypes.POINTER(ctypes.c_int),
            ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.POINTER(ctypes.c_double)),
            ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_int),
            ctypes.POINTER(ctypes.POINTER(ctypes.c_int))]
        lib.sp_step_cell_field.restype = ctypes.c_int
        lib.sp_step_cell_field.argtypes = [ctypes.POINTER(self.StepInfo), ctypes.c_int,
                                           ctypes.POINTER(ctypes.c_double)]

    def _version(self):
        try:
            f = self.lib.sp_version
        except AttributeError:
            raise OSError(f"{self.path} has no sp_version: a libsoftpack older than "
                          f"{API[0]}.{API[1]}") from None
        f.restype = ctypes.c_char_p
        f.argtypes = []
        return f().decode()

    def error_message(self):
        m = self.lib.sp_error_message()
        return m.decode(errors="replace") if m else ""


def _load_libmpi():
    for name in ("libmpi.so.40", ctypes.util.find_library("mpi"), "libmpi.so"):
        if not name:
            continue
        try:
            return ctypes.CDLL(name, mode=ctypes.RTLD_GLOBAL)
        except OSError:
            continue
    return None


_library = None


def library():
    """The Library, loaded on first use."""
    global _library
    if _library is None:
        _library = Library()
    return _library
