"""Shared fixtures of the autumnc pytest suite (run by ctest; see tests/CMakeLists.txt).

The conformance corpus is read in place from ../shared/conformance (or
$AUTUMN_SHARED_DIR/conformance); tests that need it are skipped without it.
Programs under programs/ have modules built into the package (generated/), so
tests that need the compiled engine without waiting for a compile use them.
"""
import glob
import json
import os

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SHARED = os.environ.get("AUTUMN_SHARED_DIR") or os.path.join(os.path.dirname(REPO), "shared")
CONFORMANCE = os.path.join(SHARED, "conformance")
PROGRAMS = os.path.join(REPO, "programs")
# The build tree whose CLI (autumn) the tests run beside the package: ctest sets
# AUTUMN_BUILD_DIR (the package itself is pip-installed into BUILD/venv, so its
# location says nothing about the tree); by hand, build/ of this checkout.
BUILD = os.environ.get("AUTUMN_BUILD_DIR") or os.path.join(REPO, "build")


def trace_files():
    return sorted(glob.glob(os.path.join(CONFORMANCE, "traces", "*.json")))


def load_trace(path):
    with open(path) as f:
        return json.load(f)


def conformance_program(name):
    with open(os.path.join(CONFORMANCE, "programs", name + ".sexp")) as f:
        return f.read()


def bundled_program(name):
    with open(os.path.join(PROGRAMS, name + ".au")) as f:
        return f.read()


@pytest.fixture
def stdlib():
    """The standard library text as the benchmark harness passes it (a leading newline)."""
    import autumnc
    from autumnc import _core  # noqa: F401
    with open(os.path.join(REPO, "compiler", "stdlib", "stdlib.au")) as f:
        return "\n" + f.read()


needs_corpus = pytest.mark.skipif(not os.path.isdir(CONFORMANCE), reason="conformance corpus not found")
