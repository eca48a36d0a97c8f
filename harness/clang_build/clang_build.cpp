// clang_build — a module compiled and linked by the Clang and lld libraries.
//
// The plugin does in one process what `clang++ -shared ...` does in three
// (driver, cc1, ld): the driver (clang::driver::Driver) plans the compilation
// from the ordinary command line, exactly as the clang++ binary would, which
// finds the gcc toolchain, the C++ headers and the crt files; the compile job's
// cc1 arguments become a CompilerInvocation run by a CompilerInstance with
// EmitObjAction (the object goes to the driver's temporary file); the link
// job's arguments, meant for the system linker, are given to lld's ELF driver,
// which accepts GNU ld's. Nothing here knows about Autumn: module_build passes
// the command line, the precompiled header included. Measurements and the
// decision not to make this the default: docs/design.md, "The module's compiler".
#include "harness/clang_build/clang_build.h"

#include <clang/Basic/Diagnostic.h>
#include <clang/Basic/DiagnosticOptions.h>
#include <clang/Basic/Version.h>
#include <clang/CodeGen/CodeGenAction.h>
#include <clang/Driver/Compilation.h>
#include <clang/Driver/Driver.h>
#include <clang/Driver/Job.h>
#include <clang/Driver/Tool.h>
#include <clang/Frontend/CompilerInstance.h>
#include <clang/Frontend/CompilerInvocation.h>
#include <clang/Frontend/TextDiagnosticPrinter.h>
#include <lld/Common/CommonLinkerContext.h>
#include <lld/Common/Driver.h>
#include <llvm/Support/Host.h>
#include <llvm/Support/TargetSelect.h>
#include <llvm/Support/raw_ostream.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace {

// Initialises LLVM's native target once per process.
void init_llvm() {
  static std::once_flag once;
  std::call_once(once, [] {
    llvm::InitializeNativeTarget();
    llvm::InitializeNativeTargetAsmPrinter();
    llvm::InitializeNativeTargetAsmParser();
  });
}

// Runs the driver's compile job in this process; false with the diagnostics in `out`.
bool compile(const clang::driver::Command& job, clang::DiagnosticsEngine& diags, llvm::raw_ostream& out) {
  auto invocation = std::make_shared<clang::CompilerInvocation>();
  if (!clang::CompilerInvocation::CreateFromArgs(*invocation, job.getArguments(), diags)) return false;
  clang::CompilerInstance ci;
  ci.setInvocation(std::move(invocation));
  ci.setVerboseOutputStream(out);  // "N errors generated." too: never the host's stderr
  ci.createDiagnostics(diags.getClient(), /*ShouldOwnClient=*/false);
  clang::EmitObjAction action;
  return ci.ExecuteAction(action);
}

// Runs the driver's link job with lld; its messages go to `log`. One link at a
// time per process: lld keeps its state in globals.
bool link(const clang::driver::Command& job, llvm::raw_ostream& log) {
  static std::mutex one_at_a_time;
  std::lock_guard<std::mutex> lock(one_at_a_time);
  std::vector<const char*> args{"ld.lld"};
  for (const char* a : job.getArguments()) args.push_back(a);
  const bool ok = lld::elf::link(args, log, log, /*exitEarly=*/false, /*disableOutput=*/false);
  lld::CommonLinkerContext::destroy();  // lld's state is global: reset it for the next link
  return ok;
}

// Plans the jobs and runs them; every message goes to `out`.
bool build(const std::vector<const char*>& args, llvm::raw_ostream& out) {
  llvm::IntrusiveRefCntPtr<clang::DiagnosticOptions> options = new clang::DiagnosticOptions();
  clang::TextDiagnosticPrinter printer(out, &*options);
  clang::DiagnosticsEngine diags(new clang::DiagnosticIDs(), &*options, &printer, /*ShouldOwnClient=*/false);
  clang::driver::Driver driver(args[0], llvm::sys::getProcessTriple(), diags);
  driver.setCheckInputsExist(false);
  std::unique_ptr<clang::driver::Compilation> plan(driver.BuildCompilation(args));
  if (!plan || diags.hasErrorOccurred()) return false;
  struct Cleanup {  // the driver's temporary object file, whatever happens
    clang::driver::Compilation& c;
    ~Cleanup() { c.CleanupFileList(c.getTempFiles()); }
  } cleanup{*plan};
  bool linked = false;
  for (const clang::driver::Command& job : plan->getJobs()) {
    const std::string tool = job.getCreator().getName();
    if (tool == "clang") {
      if (!compile(job, diags, out)) return false;
    } else if (tool == "GNU::Linker") {
      if (!link(job, out)) return false;
      linked = true;
    } else {
      out << "autumn_clang_build: unexpected job " << tool << "\n";
      return false;
    }
  }
  if (!linked) out << "autumn_clang_build: the driver planned no link\n";
  return linked;
}

}  // namespace

extern "C" int autumn_clang_build(int argc, const char* const* argv, char* log, size_t log_cap) {
  init_llvm();
  std::string messages;
  llvm::raw_string_ostream out(messages);
  const bool ok = argc > 1 && build(std::vector<const char*>(argv, argv + argc), out);
  out.flush();
  if (log && log_cap > 0) {
    const size_t n = std::min(messages.size(), log_cap - 1);
    std::memcpy(log, messages.data(), n);
    log[n] = 0;
  }
  return ok ? 0 : 1;
}

extern "C" const char* autumn_clang_version(void) { return CLANG_VERSION_STRING; }
