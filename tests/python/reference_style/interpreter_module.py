# The one file that switches a script written for Autumn.cpp's interpreter_module to autumnc.
from autumnc.interpreter_module import *  # noqa: F401,F403
