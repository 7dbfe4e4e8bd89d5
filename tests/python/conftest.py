"""Shared fixtures of the Python package's tests (ctest -L python).

Run by ctest with PYTHONPATH=build/python and SOFTPACK_LIBRARY set
(tests/CMakeLists.txt); by hand from the source tree:
    PYTHONPATH=src/python SOFTPACK_LIBRARY=build/libsoftpack.so \
        /usr/bin/python3 -m pytest -q tests/python
"""
import copy
import os

import pytest

SOURCE_DIR = os.environ.get("SOFTPACK_SOURCE_DIR") or \
    os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))

# Two cells in the paper's ellipse on a coarse mesh (refinements 3: 401
# nodes): a run of a few steps takes a fraction of a second.
SMALL = {
    "mesh": {"type": "ellipse", "refinements": 3, "semi_x": 0.5, "semi_y": 0.25,
             "buffer_layers": 2, "buffer_width": 0.1},
    "model": {"alpha": 4, "kappa": 1.0e-3, "lambda": 100, "lambda_b": 100, "mobility": 1},
    "time": {"dt": 2.0e-4, "t_end": 0.01, "max_steps": 6},
    "cells": [{"x": -0.2, "y": 0.0, "radius": 0.13}, {"x": 0.12, "y": 0.02, "radius": 0.11}],
    "output": {"every": 2, "pictures": False},
}


@pytest.fixture
def small():
    return copy.deepcopy(SMALL)


@pytest.fixture
def source_dir():
    return SOURCE_DIR


def csv_rows(path):
    """A CSV file as (header, rows of floats; "" -> None): read without the
    package, to compare with what it returns."""
    import csv
    with open(path) as f:
        r = list(csv.reader(f))
    return r[0], [[float(x) if x != "" else None for x in row] for row in r[1:]]
