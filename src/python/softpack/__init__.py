"""softpack: run softpack scenes from Python (ctypes over libsoftpack's
public C API, src/public/run.h).  docs/python.md.

    import softpack
    res = softpack.run({"mesh": {"type": "ellipse", "refinements": 3},
                        "time": {"t_end": 1e-3},
                        "cells": [{"x": 0, "y": 0, "radius": 0.1}]},
                       out="out/one", on_step=lambda s: print(s.step, s.masses))
    res.energy          # energy.csv as a DataFrame (numpy array without pandas)
"""

from ._capi import library_path
from ._outputs import Fields, read_csv, read_vtu
from ._run import (RunResult, SceneError, SoftpackError, SolverError, StepInfo,
                   key_of_message, request_stop, run, scene_text)
from ._scene import label_initial, read_label_image, write_label_nifti, write_label_png

__all__ = ["run", "RunResult", "StepInfo", "SoftpackError", "SceneError", "SolverError",
           "Fields", "read_vtu", "read_csv", "label_initial", "read_label_image", "write_label_png",
           "write_label_nifti", "library_path", "key_of_message", "scene_text",
           "library_version", "request_stop", "__version__"]


def library_version():
    """libsoftpack's version (sp_version())."""
    from ._capi import library
    return library().version


def __getattr__(name):
    # __version__ on first use: loading the library at import would make
    # "import softpack" fail where only its readers are wanted
    if name == "__version__":
        try:
            return library_version()
        except OSError:
            try:
                from . import _build
                return _build.VERSION
            except ImportError:
                pass
            try:
                from . import _install
                return _install.VERSION
            except ImportError:
                raise
    raise AttributeError(name)
