"""The package's ctypes structures (src/python/softpack/_capi.py) have the
C layout of the public headers this build compiled (tests/python/abi_layout.c
prints sizeof and offsetof; ctest gives its path in SOFTPACK_ABI_LAYOUT), and
the library's version is the one they mirror (_capi.API)."""
import json
import os
import subprocess

import pytest

from softpack import _capi

LAYOUT = os.environ.get("SOFTPACK_ABI_LAYOUT")


@pytest.mark.skipif(not LAYOUT, reason="SOFTPACK_ABI_LAYOUT: the built abi_layout program")
def test_ctypes_layout_is_the_headers():
    c = json.loads(subprocess.run([LAYOUT], capture_output=True, text=True, check=True).stdout)
    lib = _capi.library()
    assert c["api"] == "%d.%d" % lib.api == "%d.%d" % _capi.API, (c["api"], lib.version)
    py = {"cell_obs": lib.CellObs, "step_info": lib.StepInfo, "attempt": _capi.Attempt,
          "run_summary": _capi.RunSummary, "restart": _capi.Restart}
    for name, fields in c.items():
        if name == "api":
            continue
        cls = py[name]
        assert fields.pop("size") == _capi.ctypes.sizeof(cls), name
        for field, offset in fields.items():
            assert getattr(cls, field).offset == offset, (name, field)
