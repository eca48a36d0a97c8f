// generated/ must be exactly what the current autumnc emits for programs/.
// To accept a change: bash scripts/regenerate.sh
#include <gtest/gtest.h>

#include <set>

#include "compiler/emit/emit_module.hpp"
#include "test_support.hpp"

namespace autumn::generated_test {
namespace {

TEST(Generated, EveryModuleMatchesTheCurrentEmitter) {
  const auto programs = testing::files_in(testing::source_dir() / "programs", ".au");
  ASSERT_FALSE(programs.empty());
  std::set<std::string> expected;
  for (const auto& p : programs) {
    ModuleSource src;
    src.name = module_identifier(p.stem().string());
    src.program_path = "programs/" + p.filename().string();
    src.program_text = testing::read_text(p);
    expected.insert(src.name + ".cpp");
    const auto gen = testing::source_dir() / "generated" / (src.name + ".cpp");
    ASSERT_TRUE(std::filesystem::exists(gen)) << gen << " is missing; run scripts/regenerate.sh";
    EXPECT_EQ(testing::read_text(gen), emit_module(src))
        << gen << " is stale: regenerating would change it; run scripts/regenerate.sh";
  }
  for (const auto& g : testing::files_in(testing::source_dir() / "generated", ".cpp"))
    EXPECT_TRUE(expected.count(g.filename().string())) << g << " has no program in programs/";
}

}  // namespace
}  // namespace autumn::generated_test
