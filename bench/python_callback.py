#!/usr/bin/python3
"""What a Python step callback costs (docs/python.md, "Overhead").

    PYTHONPATH=build/python OMP_NUM_THREADS=1 bench/python_callback.py [SCENE] [--repeat N]

Runs SCENE (default inputs/default.yaml) N times (default 2) each way,
alternating: softpack.run without on_step, and with an on_step that reads
every observable of every step as numpy arrays (masses, centres, moments,
axes, inertia, volumes, names) and keeps a little of it. Prints each run's
wall time, the fastest of each way and their ratio, and the time spent
inside the callback (the Python side of every step: building the StepInfo,
the user's function), measured around it, over the run's time: that share
does not depend on the machine's noise as the ratio does.
"""
import argparse
import os
import platform
import sys
import tempfile
import time

import numpy as np

import softpack

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("scene", nargs="?", default=os.path.join(HERE, "..", "inputs", "default.yaml"))
    p.add_argument("--repeat", type=int, default=2)
    a = p.parse_args()
    overrides = {"output.pictures": False}
    plain, watched, shares = [], [], []
    with tempfile.TemporaryDirectory(prefix="softpack-bench-") as tmp:
        for i in range(a.repeat):
            t0 = time.perf_counter()
            r0 = softpack.run(a.scene, out=os.path.join(tmp, f"plain{i}"), overrides=overrides)
            plain.append(time.perf_counter() - t0)

            inside = [0.0]
            kept = []

            def watch(s):
                obs = (s.masses, s.centres, s.moments, s.axes, s.inertia, s.volumes, s.names)
                kept.append((s.step, s.t, float(obs[0].sum()), float(np.abs(obs[3]).max())))
                return False

            # the callback's whole Python side: the trampoline (StepInfo) too
            lib = softpack._capi.library()
            real = lib.Callback

            def timed(fn):
                def wrapper(ptr, user):
                    t = time.perf_counter()
                    try:
                        return fn(ptr, user)
                    finally:
                        inside[0] += time.perf_counter() - t
                return real(wrapper)

            lib.Callback = timed
            try:
                inside[0] = 0.0
                t0 = time.perf_counter()
                r1 = softpack.run(a.scene, out=os.path.join(tmp, f"watched{i}"),
                                  overrides=overrides, on_step=watch)
                watched.append(time.perf_counter() - t0)
            finally:
                lib.Callback = real
            shares.append(inside[0] / watched[-1])
            assert r0.steps == r1.steps == len(kept)
            print(f"run {i + 1}: without callback {plain[-1]:.2f} s, with {watched[-1]:.2f} s "
                  f"({r1.steps} steps; callback {inside[0] * 1e3:.1f} ms in all, "
                  f"{inside[0] / r1.steps * 1e6:.0f} us a step)")
    best0, best1 = min(plain), min(watched)
    print(f"scene {os.path.relpath(a.scene)}: {r0.steps} steps")
    print(f"fastest without callback {best0:.3f} s, with {best1:.3f} s: ratio {best1 / best0:.4f}")
    print(f"time inside the callback / run time: {100 * max(shares):.3f} % (largest of {a.repeat})")
    print(f"libsoftpack {softpack.__version__}, Python {sys.version.split()[0]}, numpy "
          f"{np.__version__}, {platform.machine()}, {os.cpu_count()} cores, "
          f"{time.strftime('%Y-%m-%d')}")


if __name__ == "__main__":
    main()
