// fuzz_emit — libFuzzer target: autumnc's lowering and module emitter.
//
// Every input is emitted twice, in process: once through the lowering (which
// loads the program and specialises it where it can; a program that does not
// load gives the embedded module with its error) and once embedded. A crash,
// hang or sanitizer report in the lowering is found at full speed. The program
// is loaded once per input (emit_module loads it; a separate load first was a
// seventh of the target's time). Whether the emitted C++ compiles is too
// slow to ask per input (seconds each), so this target only checks what can be
// checked cheaply (both modules' text is escaped: printable ASCII and
// newlines only), and scripts/fuzz.sh compiles the modules of a sample of
// the corpus afterwards (fuzz/compile_sample.sh).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "compiler/emit/emit_module.hpp"

namespace {

bool escaped(const std::string& source) {
  for (unsigned char c : source)
    if (c != '\n' && (c < 0x20 || c >= 0x7f)) return false;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  autumn::ModuleSource src;
  src.name = "fuzz";
  src.program_path = "fuzz.au";
  src.program_text = text;
  if (!escaped(autumn::emit_module(src))) std::abort();
  src.force_embedded = true;
  if (!escaped(autumn::emit_module(src))) std::abort();
  return 0;
}
