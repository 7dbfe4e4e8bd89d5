"""The shell tests' assertions (tests/*.sh run their checks in Python with
PYTHONPATH at tests/): check() prints each result, done() the verdict and
exits 1 if any check failed."""
import sys

_failed = False


def check(cond, what):
    """Print 'ok:' or 'FAIL:' and what was checked; remember a failure."""
    global _failed
    print(("ok:   " if cond else "FAIL: ") + what)
    _failed = _failed or not cond


def done():
    """PASS or FAILED, and the exit status."""
    print("FAILED" if _failed else "PASS")
    sys.exit(1 if _failed else 0)
