#include "compiler/emit/emit_module.hpp"

#include "compiler/analyse/program.hpp"
#include "compiler/lower/lower.hpp"
#include "compiler/lower/print_cpp.hpp"
#include "runtime/fnv1a.hpp"

#include <cctype>
#include <cstdio>

namespace autumn {

uint64_t module_source_hash(const std::string& text, const std::optional<std::string>& trigger) {
  uint64_t h = fnv1a(std::string_view("\0", 1), fnv1a(text));
  if (trigger) h = fnv1a(*trigger, fnv1a(std::string_view("\1", 1), h));
  return h;
}

std::string module_identifier(const std::string& stem) {
  std::string id;
  for (char c : stem) id += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  if (id.empty() || std::isdigit(static_cast<unsigned char>(id[0]))) id = "m_" + id;
  return id;
}

// One line of text safe inside a // comment (no line breaks, printable ASCII).
static std::string comment_text(const std::string& text) {
  std::string out;
  for (unsigned char c : text) out += c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?';
  return out;
}

static std::string table_and_entry(const ModuleSource& src, const std::string& hash) {
  std::string out;
  out += "const autumn_module_v1 kTable = autumn::ModuleExporter<MakeEnvironment>::table(kName, " + hash + ");\n\n";
  out += "}  // namespace\n\n";
  out += "extern \"C\" const autumn_module_v1* autumn_module_" + src.name + "(void) { return &kTable; }\n\n";
  out += "#ifdef AUTUMN_MODULE_SHARED\n";
  out += "extern \"C\" __attribute__((visibility(\"default\"))) const autumn_module_v1* autumn_module_v1_entry(void) {\n";
  out += "  return &kTable;\n";
  out += "}\n";
  out += "#endif\n";
  return out;
}

static std::string specialised_module(const ModuleSource& src, const Lowered& lowered, const std::string& hash) {
  std::string out;
  out += "// Lowering: specialised, " + std::to_string(lowered.dynamic_sites.size()) + " dynamic site(s). State is\n";
  out += "// plain data (a snapshot is a value copy); every call is inlined, so the dynamic\n";
  out += "// scopes of the source are resolved here.\n";
  for (const std::string& d : lowered.dynamic_sites) out += "//   dynamic site: " + comment_text(d) + "\n";
  out += "#include <cmath>\n#include <cstdint>\n#include <memory>\n#include <vector>\n\n";
  out += "#include \"runtime/compiled_support.hpp\"\n";
  out += "#include \"runtime/module_export.hpp\"\n\n";
  out += "namespace {\n\n";
  out += "using namespace autumn::rt;\n\n";
  out += "const char kName[] = \"" + src.name + "\";\n\n";
  out += lowered.code + "\n";
  out += "struct MakeEnvironment {\n";
  out += "  std::unique_ptr<autumn::Environment> operator()() const {\n";
  out += "    return std::make_unique<autumn::rt::CompiledEnvironment<Prog>>();\n";
  out += "  }\n";
  out += "};\n\n";
  return out + table_and_entry(src, hash);
}

// The program text run by the interpreter inside the module. Texts are escaped
// byte by byte (no raw strings: nothing in a program can end the literal).
static std::string embedded_module(const ModuleSource& src, const Lowered& lowered, const std::string& hash) {
  std::string out;
  out += "// Lowering: embedded (" + comment_text(lowered.reason) + ").\n";
  out += "// The program text below runs on the reference-exact interpreter inside this\n";
  out += "// module, which is exact for every program.\n";
  out += "#include <memory>\n\n";
  out += "#include \"compiler/analyse/program.hpp\"\n";
  out += "#include \"compiler/interpret/interpreted_env.hpp\"\n";
  out += "#include \"runtime/module_export.hpp\"\n\n";
  out += "namespace {\n\n";
  out += "const char kName[] = \"" + src.name + "\";\n\n";
  out += "const char kSource[] = " + lower::cpp_string_literal(src.program_text) + ";\n\n";
  if (src.trigger) out += "const char kTrigger[] = " + lower::cpp_string_literal(*src.trigger) + ";\n\n";
  out += "struct MakeEnvironment {\n";
  out += "  std::unique_ptr<autumn::Environment> operator()() const {\n";
  out += "    static const std::shared_ptr<const autumn::Program> program =\n";
  out += "        autumn::load_program(autumn::SourceFile{\"" + src.name + "\", std::string(kSource, sizeof kSource - 1)}" +
         (src.trigger ? ", std::string(kTrigger, sizeof kTrigger - 1)" : std::string()) + ");\n";
  out += "    return std::make_unique<autumn::InterpretedEnvironment>(program);\n";
  out += "  }\n";
  out += "};\n\n";
  return out + table_and_entry(src, hash);
}

std::string emit_module(const ModuleSource& src, Lowered* report) {
  char hash[32];
  std::snprintf(hash, sizeof hash, "0x%016llxULL",
                static_cast<unsigned long long>(module_source_hash(src.program_text, src.trigger)));
  Lowered lowered;
  if (src.force_embedded) {
    lowered.reason = "specialisation turned off";
  } else {
    try {
      auto program = load_program(SourceFile{src.program_path, src.program_text}, src.trigger);
      lowered = lower_program(*program, src.name);
    } catch (const CompileError& e) {
      lowered.reason = e.formatted();
    }
  }
  std::string out;
  out += "// Generated by autumnc from " + comment_text(src.program_path) + ". Do not edit: regenerate it with\n";
  out += "// `autumnc " + comment_text(src.program_path) + "` (generated/, the built-in modules: scripts/regenerate.sh).\n";
  out += "//\n";
  out += lowered.ok ? specialised_module(src, lowered, hash) : embedded_module(src, lowered, hash);
  if (report) {
    *report = std::move(lowered);
    report->code.clear();
  }
  return out;
}

}  // namespace autumn
