// module — autumnc._core, the extension module behind the autumnc package.
//
// Exceptions: CompileError (a program, trigger or expression that does not
// read or parse) becomes autumnc.ParseError; a runtime error of the program
// becomes autumnc.AutumnRuntimeError; both derive from RuntimeError, which is
// what the reference's binding raises. std::invalid_argument becomes ValueError
// (pybind11's default), so bad actions and arguments are ValueErrors.
#include <iostream>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "compiler/analyse/program.hpp"
#include "compiler/read/source.hpp"
#include "python/src/bindings.hpp"
#include "python/src/colours.hpp"
#include "python/src/module_broker.hpp"
#include "python/src/session.hpp"

namespace pb = pybind11;

PYBIND11_MODULE(_core, m) {
  m.doc() = "autumnc: Autumn environments, compiled (the C++ core of the autumnc package)";
  static pb::exception<autumn::CompileError> parse_error(m, "ParseError", PyExc_RuntimeError);
  static pb::exception<autumn::py::SessionError> runtime_error(m, "AutumnRuntimeError", PyExc_RuntimeError);
  pb::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const autumn::CompileError& e) {
      parse_error(e.formatted().c_str());
    } catch (const autumn::py::SessionError& e) {
      runtime_error(e.what());
    }
  });
  autumn::py_bind::bind_interpreter(m);
  autumn::py_bind::bind_envs(m);
  autumn::py_bind::bind_agent(m);
  autumn::py_bind::bind_distributed(m);
  m.def("colour_names", &autumn::py::colour_names, "Colour names by observation id");
  m.attr("__version__") = AUTUMNC_VERSION;
  m.def(
      "stdlib", [] { return autumn::stdlib_text(); },
      "The bundled standard library's text: what an empty stdlib argument (\"\") stands for, and what "
      "compiled modules are built with");
  // At exit (autumnc/__init__.py): compiles this process started finish, so the
  // next run finds their modules (a compile killed half way leaves nothing);
  // the wait is said on stderr rather than a silent pause.
  m.def("_wait_for_compiles", [] {
    pb::gil_scoped_release release;
    autumn::py::wait_for_compiles([](size_t n) {
      // One write: a compile thread may be printing its own line at the same moment.
      std::cerr << ("autumnc: waiting for " + std::to_string(n) + " module compile" + (n == 1 ? "" : "s") +
                    " this script started (the next run uses " + (n == 1 ? "it" : "them") + ")\n");
    });
  });
}
