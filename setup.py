"""setup.py — the build step of `pip install .` (pyproject.toml): the project's CMake builds
autumnc._core, setuptools packages it with python/autumnc.

setuptools copies python/autumnc/*.py and the package data (the type stubs
_core.pyi, the py.typed marker, play_page.html) as for any pure package; this
file's build_py then drives CMake and copies the one file CMake makes for the
package, the extension _core<EXT_SUFFIX> of the interpreter running pip:

* the tree is $AUTUMNC_CMAKE_BUILD_DIR (relative: to the checkout), else build/ in the checkout (the tree
  scripts/bootstrap.sh makes, so a built checkout installs in seconds);
* a directory without a CMakeCache.txt is configured first (Release, Ninja when
  it is on PATH, Python3_EXECUTABLE = this interpreter); an existing tree
  configured for another interpreter is refused rather than switched, since
  that would rebuild the user's tree for a Python it was not made for;
* `cmake --build TREE --target _core` then builds the extension and what it
  needs at run time (the static libraries and precompiled header that modules
  compiled on demand link and include): on a built tree an incremental no-op.

The extension keeps absolute paths into this checkout (the runtime headers)
and into the build tree (the libraries and the header): the installed package
compiles modules for new programs while both exist (docs/python.md,
"Installing"). setuptools' own scratch (build_base, egg-info) goes under
TREE/pip so that the checkout gets no new files.
"""
import glob
import os
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

HERE = os.path.dirname(os.path.abspath(__file__))


def project_version():
    with open(os.path.join(HERE, "CMakeLists.txt"), encoding="utf-8") as f:
        found = re.search(r"^project\(autumnc VERSION ([0-9.]+)", f.read(), re.M)
    if not found:
        sys.exit("setup.py: no `project(autumnc VERSION ...)` line in CMakeLists.txt")
    return found.group(1)


def cmake_tree():
    given = os.environ.get("AUTUMNC_CMAKE_BUILD_DIR")
    return os.path.abspath(os.path.join(HERE, given) if given else os.path.join(HERE, "build"))


def cached(tree, name):
    """A CMakeCache.txt entry of the tree, or None."""
    try:
        with open(os.path.join(tree, "CMakeCache.txt"), encoding="utf-8") as f:
            for line in f:
                if line.startswith(name + ":"):
                    return line.split("=", 1)[1].strip()
    except FileNotFoundError:
        pass
    return None


def run(cmd):
    print("setup.py: " + " ".join(cmd), flush=True)
    if subprocess.call(cmd) != 0:
        sys.exit(f"setup.py: `{' '.join(cmd)}` failed (its output is above)")


def build_core(tree):
    """Configures (when new) and builds the _core target; returns the extension's path."""
    if shutil.which("cmake") is None:
        sys.exit("setup.py: cmake is not on PATH (Debian: apt-get install cmake ninja-build; scripts/bootstrap.sh "
                 "installs everything the build needs)")
    # The interpreter itself, not a venv's link to it: the tree then outlives the venv.
    python = os.path.realpath(sys.executable)
    configured = cached(tree, "Python3_EXECUTABLE")
    if configured is None:
        cmd = ["cmake", "-S", HERE, "-B", tree, "-DCMAKE_BUILD_TYPE=Release", "-DPython3_EXECUTABLE=" + python]
        if shutil.which("ninja"):
            cmd += ["-G", "Ninja"]
        run(cmd)
    elif os.path.realpath(configured) != python:
        sys.exit(f"setup.py: the CMake tree {tree} is configured for {configured}, not for the Python running pip "
                 f"({python}); set AUTUMNC_CMAKE_BUILD_DIR to another directory (it is configured for this Python), "
                 f"or run pip with {configured}")
    run(["cmake", "--build", tree, "--target", "_core"])
    core = os.path.join(tree, "python", "autumnc", "_core" + sysconfig.get_config_var("EXT_SUFFIX"))
    if not os.path.isfile(core):
        made = glob.glob(os.path.join(tree, "python", "autumnc", "_core*"))
        sys.exit(f"setup.py: the build made no {core} (found: {made or 'nothing'})")
    return core


class BuildPyWithCore(build_py):
    """build_py, plus the extension built by CMake."""

    def run(self):
        stale = os.path.join(self.build_lib, "autumnc")
        if os.path.isdir(stale):  # a file removed from python/autumnc must not linger in the wheel
            shutil.rmtree(stale)
        super().run()
        core = build_core(cmake_tree())
        self.copy_file(core, os.path.join(self.build_lib, "autumnc", os.path.basename(core)))


class BinaryDistribution(Distribution):
    """A platform wheel (cp3X-...-linux_x86_64, installed to platlib): it holds a compiled extension."""

    def has_ext_modules(self):
        return True


SCRATCH = os.path.join(cmake_tree(), "pip")
os.makedirs(SCRATCH, exist_ok=True)  # egg_info wants its egg_base to exist

setup(
    version=project_version(),
    packages=["autumnc"],
    package_dir={"": "python"},
    package_data={"autumnc": ["*.html", "*.pyi", "py.typed"]},
    include_package_data=False,
    zip_safe=False,
    cmdclass={"build_py": BuildPyWithCore},
    distclass=BinaryDistribution,
    options={"build": {"build_base": SCRATCH}, "egg_info": {"egg_base": SCRATCH}},
)
