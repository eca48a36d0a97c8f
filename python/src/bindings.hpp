// bindings — the pieces of the autumnc._core extension module, one per file.
#pragma once
#include <pybind11/pybind11.h>

namespace autumn::py_bind {

void bind_interpreter(pybind11::module_& m);
void bind_envs(pybind11::module_& m);
void bind_agent(pybind11::module_& m);
void bind_distributed(pybind11::module_& m);

}  // namespace autumn::py_bind
