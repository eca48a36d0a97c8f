"""autumnc: Autumn environments in Python, on the compiled engine.

The package wraps the C++ core (autumnc._core, built by the project's CMake):

* ``autumnc.interpreter_module.Interpreter`` -- a drop-in for the reference's
  pybind11 ``interpreter_module`` (Autumn.cpp), same methods and results;
* ``autumnc.Env`` / ``autumnc.VecEnv`` -- Gymnasium-shaped environments with
  uint8 colour-id observations, the batched one stepped in C++ threads;
* ``autumnc.solve``, ``autumnc.baseline_random``, ``autumnc.make_task``, ``autumnc.Program`` -- the
  simulator agent and program tools, returning what the CLI prints as JSON.

Programs are compiled on demand through the module cache; see docs/python.md.
"""
import atexit as _atexit

from . import _core
from ._core import AutumnRuntimeError, ParseError, EnvState, colour_names, stdlib, __version__
from .interpreter_module import Interpreter
from .envs import Env, VecEnv
from .spaces import Box, Discrete
from .agent import Program, baseline_random, make_task, solve

__all__ = [
    "AutumnRuntimeError", "Box", "Discrete", "Env", "EnvState", "Interpreter", "ParseError",
    "Program", "VecEnv", "baseline_random", "colour_names", "make_task", "solve", "stdlib",
]

# A module compile still running at exit would outlive the C++ statics it uses.
_atexit.register(_core._wait_for_compiles)

from . import gym_adapter as _gym_adapter  # registers with gymnasium when it is installed

_gym_adapter.register()
