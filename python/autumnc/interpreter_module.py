"""Drop-in replacement for the reference's ``interpreter_module``.

A script written for BasisResearch/Autumn.cpp's pybind11 module switches by
importing this one instead::

    from autumnc.interpreter_module import Interpreter

The class has every method of the reference's binding with the same names,
arguments, defaults, return strings and exceptions (docs/python.md lists the
few deliberate differences), and a few additions: ``clone()``, ``get_state()``,
``set_state()``, ``state_hash()``, ``render_grid()``, ``palette()``, ``engine``.
"""
from ._core import Interpreter

__all__ = ["Interpreter"]
