"""The package as pip installs it: where it came from, what ships with it, and stubs that match.

Under ctest the suite runs with the Python of BUILD/venv, into which the fixture
python_pip_install (tests/python/pip_install.sh) has pip-installed this
checkout; AUTUMNC_EXPECT_VENV names that venv, and the first test fails when
autumnc came from anywhere else (a PYTHONPATH, the build tree). Then: the type
information ships (py.typed, _core.pyi), the version is the CMake project's
and pip's, the stubs name exactly what the extension binds (every function and
class, every public member, every argument name and which have defaults, read
from pybind11's signature lines), and help() has real documentation.
"""
import ast
import importlib.metadata
import inspect
import os
import re

import pytest

import autumnc
from autumnc import _core
from conftest import REPO

PACKAGE = os.path.dirname(os.path.abspath(autumnc.__file__))
EXPECT_VENV = os.environ.get("AUTUMNC_EXPECT_VENV")


def project_version():
    with open(os.path.join(REPO, "CMakeLists.txt")) as f:
        return re.search(r"^project\(autumnc VERSION ([0-9.]+)", f.read(), re.M).group(1)


@pytest.mark.skipif(not EXPECT_VENV, reason="AUTUMNC_EXPECT_VENV not set (ctest sets it)")
def test_autumnc_is_the_pip_installed_package():
    venv = os.path.realpath(EXPECT_VENV)
    here = os.path.realpath(autumnc.__file__)
    assert here.startswith(venv + os.sep) and os.sep + "site-packages" + os.sep in here, \
        f"autumnc was imported from {here}, not from the venv {venv}"
    assert os.path.realpath(_core.__file__).startswith(os.path.dirname(here) + os.sep)
    assert importlib.metadata.version("autumnc") == autumnc.__version__
    files = {str(f) for f in importlib.metadata.files("autumnc")}
    assert {"autumnc/py.typed", "autumnc/_core.pyi", "autumnc/play_page.html"} <= files


def test_type_information_ships():
    assert os.path.isfile(os.path.join(PACKAGE, "py.typed"))
    assert os.path.isfile(os.path.join(PACKAGE, "_core.pyi"))


def test_version_is_the_project_version():
    assert autumnc.__version__ == _core.__version__ == project_version()


# --- the stubs against the extension ----------------------------------------------------

def stub_tree():
    with open(os.path.join(PACKAGE, "_core.pyi")) as f:
        return ast.parse(f.read())


def stub_params(fn):
    """[(name, has_default)] of a stubbed function, self left out; a
    positional-only argument's name is pybind11's for an unnamed one, argN."""
    a = fn.args
    positional = a.posonlyargs + a.args
    defaults = [False] * (len(positional) - len(a.defaults)) + [True] * len(a.defaults)
    posonly = [p.arg for p in a.posonlyargs if p.arg != "self"]
    names = ["self"] * (len(a.posonlyargs) - len(posonly)) + [f"arg{i}" for i in range(len(posonly))]
    out = list(zip(names + [p.arg for p in a.args], defaults))
    out += [(p.arg, d is not None) for p, d in zip(a.kwonlyargs, a.kw_defaults)]
    return [p for p in out if p[0] != "self"]


def split_top(text):
    """Splits pybind11's argument list on the commas outside brackets."""
    parts, depth, cur = [], 0, ""
    for ch in text:
        if ch in "[(":
            depth += 1
        elif ch in "])":
            depth -= 1
        if ch == "," and depth == 0:
            parts.append(cur.strip())
            cur = ""
        else:
            cur += ch
    if cur.strip():
        parts.append(cur.strip())
    return parts


def signature_params(line, name):
    """[(name, has_default)] of one pybind11 signature line `name(a: T, b: T = x) -> R`."""
    assert line.startswith(name + "("), f"{name}: no pybind11 signature line in {line!r}"
    inner = line[len(name) + 1:line.rindex(") ->")]
    params = [(p.split(":")[0].strip(), "=" in p) for p in split_top(inner)]
    return [p for p in params if p[0] != "self"]


def bound_params(obj, name):
    """[[(name, has_default)]], one list per overload, from pybind11's signature
    lines: the first docstring line, or for an overloaded function the numbered
    lines `1. name(...) -> R` after "Overloaded function."."""
    lines = (obj.__doc__ or "").splitlines()
    if len(lines) > 1 and lines[1] == "Overloaded function.":
        numbered = [re.sub(r"^\d+\. ", "", l) for l in lines if re.match(r"^\d+\. " + re.escape(name) + r"\(", l)]
        assert numbered, f"{name}: overloaded, but no numbered signature lines"
        return [signature_params(l, name) for l in numbered]
    return [signature_params(lines[0] if lines else "", name)]


def test_stubs_name_what_the_extension_binds():
    tree = stub_tree()
    stubbed = {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            stubbed[node.name] = node
        elif isinstance(node, ast.AnnAssign):
            stubbed[node.target.id] = node
    bound = {n for n in vars(_core) if not (n.startswith("__") and n != "__version__")}
    helpers = {n for n in stubbed if n.startswith("_") and n not in bound and n != "__version__"}
    assert helpers <= {"_ActionId"}, helpers  # type aliases of the stub only
    assert bound == set(stubbed) - helpers

    for name, node in stubbed.items():
        obj = getattr(_core, name, None)
        if isinstance(node, ast.FunctionDef):
            assert [stub_params(node)] == bound_params(obj, name), name
        if isinstance(node, ast.ClassDef) and not issubclass(obj, BaseException):
            members = {}  # name -> [definitions]: several for an @overload, in order
            for m in node.body:
                if isinstance(m, ast.FunctionDef):
                    members.setdefault(m.name, []).append(m)
            own = {n for n in vars(obj) if not n.startswith("_") or n in ("__copy__", "__deepcopy__")}
            if (getattr(vars(obj).get("__init__"), "__doc__", None) or "").startswith("__init__("):
                own.add("__init__")  # a bound constructor (not pybind11's "No constructor defined")
            assert own == {n for n in members if not n.startswith("__") or n in own}, name
            for m, fns in members.items():
                attr = inspect.getattr_static(obj, m)
                if isinstance(attr, property) or m in ("__getstate__", "__setstate__"):
                    continue
                assert [stub_params(fn) for fn in fns] == bound_params(getattr(obj, m), m), f"{name}.{m}"


# --- documentation ---------------------------------------------------------------------

def test_help_explains_env_and_interpreter():
    text = inspect.getdoc(autumnc.Env)
    for words in ("5 + y*W + x", "uint8", "engine", "max_episode_steps", "trigger", "colour_names"):
        assert words in text, words
    assert "action id" in inspect.getdoc(autumnc.Env.step)
    assert "seed" in inspect.getdoc(autumnc.Env.reset)
    bare = {"Run a script", "Execute a step", "Render all", "Get background", "Restore environment"}
    for name, member in vars(autumnc.Interpreter).items():
        if callable(member) and not name.startswith("_"):
            doc = inspect.getdoc(getattr(autumnc.Interpreter, name)).splitlines()
            assert len(doc) > 1 and doc[1:] and not (set(doc) & bare), f"Interpreter.{name}: {doc}"
    assert "to_bytes" in inspect.getdoc(autumnc.EnvState)
