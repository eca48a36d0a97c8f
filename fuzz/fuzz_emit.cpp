// fuzz_emit — libFuzzer target: autumnc's lowering and module emitter.
//
// Every input that loads is lowered and emitted twice (specialised where the
// lowering can, and embedded), in process: a crash, hang or sanitizer report in
// the lowering is found at full speed. Whether the emitted C++ compiles is too
// slow to ask per input (seconds each), so this target only checks what can be
// checked cheaply (the embedded module's text is escaped: printable ASCII and
// newlines only), and scripts/fuzz.sh compiles the modules of a sample of the
// corpus afterwards (fuzz/compile_sample.sh).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "compiler/analyse/program.hpp"
#include "compiler/emit/emit_module.hpp"
#include "compiler/lower/lower.hpp"

namespace {

bool escaped(const std::string& source) {
  for (unsigned char c : source)
    if (c != '\n' && (c < 0x20 || c >= 0x7f)) return false;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    autumn::load_program(autumn::SourceFile{"fuzz.au", text});
  } catch (const autumn::CompileError&) {
    return 0;
  }
  autumn::ModuleSource src;
  src.name = "fuzz";
  src.program_path = "fuzz.au";
  src.program_text = text;
  autumn::Lowered report;
  (void)autumn::emit_module(src, &report);
  src.force_embedded = true;
  if (!escaped(autumn::emit_module(src))) std::abort();
  return 0;
}
