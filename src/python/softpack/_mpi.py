"""MPI for the library's calls: initialised by mpi4py when it is used (a
``comm=`` given, or mpi4py.MPI already imported), else by this module
through ctypes on libmpi (MPI_Init if not initialised, MPI_Finalize at
exit).  Communicators are passed to C as Open MPI handles (pointers)."""

import atexit
import ctypes
import sys

from . import _capi

_we_initialised = False


def _mpi():
    lib = _capi.library()
    if lib.mpi is None:
        raise OSError("libmpi not found (softpack needs Open MPI's libmpi.so.40)")
    return lib.mpi


def _finalize():
    m = _mpi()
    flag = ctypes.c_int(0)
    m.MPI_Finalized(ctypes.byref(flag))
    if not flag.value:
        m.MPI_Finalize()


def mpi4py_in_use():
    return "mpi4py.MPI" in sys.modules


def ensure_initialised(want_mpi4py=False):
    """MPI initialised: by mpi4py if wanted or already imported, else here."""
    global _we_initialised
    if want_mpi4py or mpi4py_in_use():
        from mpi4py import MPI  # noqa: F401  (initialises MPI)
        return
    m = _mpi()
    flag = ctypes.c_int(0)
    m.MPI_Initialized(ctypes.byref(flag))
    if flag.value:
        return
    m.MPI_Init.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    rc = m.MPI_Init(None, None)
    if rc != 0:
        raise OSError(f"MPI_Init failed ({rc})")
    _we_initialised = True
    atexit.register(_finalize)


def comm_handle(comm=None):
    """The C MPI_Comm for @p comm (an mpi4py communicator; None:
    MPI_COMM_WORLD) as a ctypes.c_void_p."""
    if comm is None:
        world = ctypes.c_char.in_dll(_mpi(), "ompi_mpi_comm_world")
        return ctypes.c_void_p(ctypes.addressof(world))
    from mpi4py import MPI
    if hasattr(MPI, "_handleof"):
        return ctypes.c_void_p(MPI._handleof(comm))
    return ctypes.c_void_p.from_address(MPI._addressof(comm))


def rank_size(handle):
    m = _mpi()
    r, s = ctypes.c_int(0), ctypes.c_int(1)
    m.MPI_Comm_rank.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_int)]
    m.MPI_Comm_size.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_int)]
    m.MPI_Comm_rank(handle, ctypes.byref(r))
    m.MPI_Comm_size(handle, ctypes.byref(s))
    return r.value, s.value


def barrier(handle):
    m = _mpi()
    m.MPI_Barrier.argtypes = [ctypes.c_void_p]
    m.MPI_Barrier(handle)
