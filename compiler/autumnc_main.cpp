// autumnc — compile an Autumn program into a C++ environment module.
//
//   autumnc PROGRAM [-o DIR] [--name NAME] [--trigger EXPR] [-v] [--strict] [--embedded]
//
// Writes DIR/NAME.cpp (compiler/emit/emit_module.hpp says what it contains),
// says so on stderr ("wrote DIR/NAME.cpp"), after one line saying how it lowered:
//
//   prog.au: specialised, 0 dynamic sites
//   prog.au: specialised, 3 dynamic sites (-v lists them)
//   prog.au: not specialised (file:line:col: why); the module embeds the interpreter
//
// --strict makes a dynamic site or a program that does not specialise an error.
// A program that cannot run is refused with a located error: one that does not
// read or parse, a GRID_SIZE that cannot be painted, or a start-up that fails (the
// interpreter starts it with the benchmark's seed 0 first: a type error it meets
// there is proven). Warnings (compiler/analyse/lint.hpp) are printed; --Werror
// makes them errors. --embedded skips the specialiser (the module embeds the
// interpreter). --dump-ir STAGE prints the lowering's IR after that stage
// (compiler/lower/ir_print.hpp) instead of writing anything.
// Exit status: 0 written, 1 the program is bad (file:line:col: error: ...) or
// --strict refused it or the file cannot be written, 2 usage (a flag, or a
// PROGRAM that names no readable file).
#include <CLI/CLI.hpp>

#include <algorithm>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "compiler/read/output.hpp"
#include "compiler/analyse/lint.hpp"
#include "compiler/analyse/program.hpp"
#include "compiler/emit/emit_module.hpp"
#include "compiler/interpret/interpreted_env.hpp"
#include "compiler/lower/lower.hpp"

namespace {

struct Options {
  std::string program_path;
  std::string out_dir = ".";
  std::string name;
  std::string trigger;
  bool verbose = false;
  bool strict = false;
  bool werror = false;
  bool embedded = false;
  std::string dump_ir;  // a lowering stage: print the IR after it instead of writing the module
};

void register_options(CLI::App& app, Options& o) {
  app.add_option("PROGRAM", o.program_path, "Autumn program (.au or .sexp)")->required();
  app.add_option("-o,--out", o.out_dir, "Output directory (created if missing)")->default_val(".");
  app.add_option("--name", o.name, "Module name (default: the program's file name)");
  app.add_option("--trigger", o.trigger, "Compile in a change-detection trigger condition");
  app.add_flag("-v,--verbose", o.verbose, "List every dynamic site with its location and reason");
  app.add_flag("--strict", o.strict, "Fail (exit 1) unless the program specialises with no dynamic site");
  app.add_flag("--Werror", o.werror, "Treat warnings as errors");
  app.add_flag("--embedded", o.embedded, "Emit the embedded module (the interpreter runs the program text)");
  std::string stages;
  for (const std::string& s : autumn::lowering_stages()) stages += (stages.empty() ? "" : ", ") + s;
  app.add_option("--dump-ir", o.dump_ir,
                 "Print the lowering's IR after STAGE on stdout instead of writing the module (" + stages + ")")
      ->check(CLI::IsMember(autumn::lowering_stages()))
      ->option_text("STAGE");
}

// --dump-ir: the IR after the stage, or why the program has none.
int dump_ir(const Options& o, const autumn::ModuleSource& src) {
  auto program = autumn::load_program(autumn::SourceFile{o.program_path, src.program_text}, src.trigger);
  autumn::LowerOptions lo;
  lo.dump_ir_after = o.dump_ir;
  const autumn::Lowered lowered = autumn::lower_program(*program, src.name, lo);
  if (!lowered.ok) {
    std::cerr << o.program_path << ": not specialised (" << lowered.reason << "): it has no lowering IR\n";
    return 1;
  }
  std::cout << lowered.ir;
  return 0;
}

// The one-line summary, and with -v one line per dynamic site.
int report(const Options& o, const autumn::Lowered& lowered) {
  const size_t n = lowered.dynamic_sites.size();
  if (!lowered.ok) {
    std::cerr << o.program_path << ": not specialised (" << lowered.reason
              << "); the module embeds the interpreter\n";
    return o.strict ? 1 : 0;
  }
  std::cerr << o.program_path << ": specialised, " << n << " dynamic site" << (n == 1 ? "" : "s");
  if (n && !o.verbose) std::cerr << " (-v lists them)";
  std::cerr << "\n";
  if (o.verbose)
    for (const std::string& d : lowered.dynamic_sites) std::cerr << "  " << d << "\n";
  return o.strict && n ? 1 : 0;
}

// Loads the program, prints its warnings and refuses one that cannot run.
bool can_run(const Options& o, const autumn::ModuleSource& src) {
  std::shared_ptr<const autumn::Program> program;
  try {
    program = autumn::load_program(autumn::SourceFile{o.program_path, src.program_text}, src.trigger);
  } catch (const autumn::CompileError& e) {
    std::cerr << e.formatted() << "\n";
    return false;
  }
  for (const auto& w : program->warnings) std::cerr << w << "\n";
  if (o.werror && !program->warnings.empty()) {
    std::cerr << autumn::warnings_as_errors(o.program_path, program->warnings.size()) << "\n";
    return false;
  }
  autumn::InterpretedEnvironment trial(program);
  if (!trial.reset(0)) {
    std::cerr << trial.error() << "\n"
              << o.program_path << ": error: the program fails at start-up (seed 0), so it cannot run\n";
    return false;
  }
  return true;
}

int run(const Options& o) {
  autumn::ModuleSource src;
  src.program_path = o.program_path;
  try {
    src.program_text = autumn::read_program_text(o.program_path);
  } catch (const autumn::CompileError& e) {
    std::cerr << e.formatted() << "\n";
    return 2;  // the PROGRAM argument names no readable file: a usage error, as in `autumn`
  }
  if (!o.trigger.empty()) src.trigger = o.trigger;
  src.force_embedded = o.embedded;
  src.name = autumn::module_identifier(
      o.name.empty() ? std::filesystem::path(o.program_path).stem().string() : o.name);
  if (!can_run(o, src)) return 1;
  if (!o.dump_ir.empty()) return dump_ir(o, src);
  autumn::Lowered lowered;
  const std::string module = autumn::emit_module(src, &lowered);
  const int status = report(o, lowered);
  if (status) return status;
  std::error_code ec;
  std::filesystem::create_directories(o.out_dir, ec);
  const auto out_path = std::filesystem::path(o.out_dir) / (src.name + ".cpp");
  if (std::string why = autumn::write_file(out_path, module); !why.empty()) {
    std::cerr << "autumnc: " << why << "\n";
    return 1;
  }
  std::cerr << "wrote " << out_path.string() << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"autumnc: compile an Autumn program into a C++ environment module"};
  app.set_version_flag("--version", "autumnc " AUTUMNC_VERSION, "Print the version and exit");
  Options o;
  register_options(app, o);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  int status = 1;
  try {
    status = run(o);
  } catch (const std::exception& e) {  // an internal error (AUTUMN_VERIFY_IR), said rather than a crash
    std::cerr << "autumnc: " << o.program_path << ": " << e.what() << "\n";
  }
  return autumn::finish_stdout("autumnc", status);
}
