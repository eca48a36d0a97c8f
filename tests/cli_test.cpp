// The autumn CLI: exit codes and one-line reasons for bad input.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "test_support.hpp"

namespace fs = std::filesystem;

namespace cli_test {
namespace {

using Result = autumn::testing::CliResult;
Result run(const std::string& args) { return autumn::testing::run_cli(args); }

std::string golden(const char* name) {
  return (autumn::testing::source_dir() / "tests/golden" / name).string();
}

TEST(Cli, RunPrintsFrames) {
  Result r = run("run " + golden("stale_occupancy.au") + " --actions noop --seed 1");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("# frame 1 (noop)"), std::string::npos) << r.out;
}

TEST(Cli, RunJsonIsATraceThatChecks) {
  const std::string json = "/tmp/autumn_cli_test_trace.json";
  // stdout only: the JSON goes to the file, notes (and sanitizer warnings) to stderr.
  Result r = autumn::testing::run_cli("run " + golden("random_colour.au") + " --seed 9 --steps 5 --json > " + json, true);
  ASSERT_EQ(r.status, 0) << r.out;
  Result c = run("check " + golden("random_colour.au") + " " + json);
  EXPECT_EQ(c.status, 0) << c.out;
  EXPECT_NE(c.out.find("matched 6/6 frames in 1 traces"), std::string::npos) << c.out;
}

// A bad --actions value is a usage error (exit 2, as the README's exit codes say), on one line.
TEST(Cli, BadActionIsAOneLineError) {
  Result r = run("run " + golden("stale_occupancy.au") + " --actions 'left,jump'");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  Result render = run("render " + golden("stale_occupancy.au") + " --actions 'jump' --out /tmp/autumn_cli_test_never.png");
  EXPECT_EQ(render.status, 2) << render.out;
  // So is a program file that does not exist, for both tools.
  EXPECT_EQ(run("run /nonexistent/prog.au").status, 2);
  EXPECT_EQ(autumn::testing::run_cli("/nonexistent/prog.au", false, "", AUTUMNC_CLI).status, 2);
  EXPECT_NE(r.out.find("action 2: unknown action 'jump'"), std::string::npos) << r.out;
}

TEST(Cli, UnknownFlagIsAUsageError) {
  Result r = run("run " + golden("stale_occupancy.au") + " --frobnicate");
  EXPECT_EQ(r.status, 2) << r.out;
}

TEST(Cli, MissingProgramIsAnError) {
  Result r = run("run /nonexistent/x.au");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("/nonexistent/x.au"), std::string::npos) << r.out;
}

TEST(Cli, MalformedProgramGivesLocatedError) {
  Result r = run("run " + (autumn::testing::source_dir() / "tests/diagnostics/unclosed_paren.au").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("unclosed_paren.au:2:1: error: unclosed '('"), std::string::npos) << r.out;
}

TEST(Cli, RuntimeErrorExitsNonZeroWithLocation) {
  Result r = run("run " + (autumn::testing::source_dir() / "tests/runtime_errors/undefined_variable.au").string() +
                 " --actions left");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("undefined_variable.au:6:22: runtime error: undefined variable 'nosuch'"), std::string::npos)
      << r.out;
}

TEST(Cli, CheckReportsMismatchAndFails) {
  const std::string json = "/tmp/autumn_cli_test_bad.json";
  FILE* f = fopen(json.c_str(), "w");
  fputs(R"({"program":"x","grid_size":5,"traces":[{"seed":0,"actions":["noop"],"frames":[)"
        R"(["black black black black black","black black black black black","black black black black black",)"
        R"("black black black black black","black black black black black"],)"
        R"(["black black black black black","black black black black black","black black black black black",)"
        R"("black black black black black","black black black black black"]]}]})",
        f);
  fclose(f);
  Result r = run("check " + golden("stale_occupancy.au") + " " + json);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("MISMATCH trace 0 (seed 0), frame 0 (after start): first differing cell (x=1, y=2): expected black, got red"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("matched 0/2 frames in 1 traces"), std::string::npos) << r.out;
}

TEST(Cli, MalformedTraceFileIsAOneLineError) {
  const std::string json = "/tmp/autumn_cli_test_malformed.json";
  FILE* f = fopen(json.c_str(), "w");
  fputs("{\"traces\": [{\"seed\": 0}]}", f);
  fclose(f);
  Result r = run("check " + golden("stale_occupancy.au") + " " + json);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("malformed trace file"), std::string::npos) << r.out;
}

TEST(Cli, TraceFileWithABadGridSizeOrNoTracesIsRefused) {
  const std::string json = "/tmp/autumn_cli_test_refused.json";
  const std::string trace = R"("traces":[{"seed":0,"actions":[],"frames":[["black"]]}])";
  for (const std::string& text : {R"({"grid_size":-5,)" + trace + "}", R"({"grid_size":"5",)" + trace + "}",
                                  std::string(R"({"grid_size":5,"traces":[]})")}) {
    FILE* f = fopen(json.c_str(), "w");
    fputs(text.c_str(), f);
    fclose(f);
    Result r = run("check " + golden("stale_occupancy.au") + " " + json);
    EXPECT_EQ(r.status, 1) << text << "\n" << r.out;
    EXPECT_NE(r.out.find(text.find("\"traces\":[]") != std::string::npos ? "the \"traces\" array is empty" : "\"grid_size\" must be"),
              std::string::npos)
        << r.out;
  }
}

// Standard output on a full disk (/dev/full): the reason on stderr and a non-zero
// exit, never a success with nothing written. stderr goes to the pipe, stdout to
// /dev/full (the redirections apply in order).
TEST(Cli, AFullDiskIsAnErrorNotAnEmptySuccess) {
  const std::string prog = golden("stale_occupancy.au");
  const std::string trace = "/tmp/autumn_cli_test_full_disk.json";
  // stdout only: a sanitizer build warns on stderr (ASan on the interpreter's stack switch)
  ASSERT_EQ(autumn::testing::run_cli("run " + prog + " --steps 3 --json > " + trace, true).status, 0);
  for (const std::string& args : {"run " + prog + " --steps 3 --json", "check " + prog + " " + trace,
                                  "difftest " + prog + " --seeds 1 --steps 5"}) {
    const std::string cmd = std::string(AUTUMN_CLI) + " " + args + " 2>&1 >/dev/full";
    FILE* p = popen(cmd.c_str(), "r");
    std::string err;
    std::array<char, 4096> buf;
    while (size_t n = fread(buf.data(), 1, buf.size(), p)) err.append(buf.data(), n);
    const int st = pclose(p);
    EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 1) << args << "\n" << err;
    EXPECT_NE(err.find("autumn: cannot write the standard output: No space left on device"), std::string::npos)
        << args << "\n" << err;
  }
  // autumnc -o: the module file is a link to /dev/full.
  const fs::path dir = fs::temp_directory_path() / "autumn_cli_test_full_disk";
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::create_symlink("/dev/full", dir / "stale_occupancy.cpp");
  Result r = autumn::testing::run_cli(prog + " -o " + dir.string(), false, "", AUTUMNC_CLI);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("cannot write " + (dir / "stale_occupancy.cpp").string() + ": No space left on device"),
            std::string::npos)
      << r.out;
  fs::remove_all(dir);
}

// Both tools say their version (the project's, CMakeLists.txt) and exit 0.
TEST(Cli, VersionOfBothTools) {
  Result a = autumn::testing::run_cli("--version", true);
  EXPECT_EQ(a.status, 0) << a.out;
  EXPECT_EQ(a.out.rfind("autumn 0.", 0), 0u) << a.out;
  Result c = autumn::testing::run_cli("--version", true, "", AUTUMNC_CLI);
  EXPECT_EQ(c.status, 0) << c.out;
  EXPECT_EQ(c.out.substr(c.out.find(' ')), a.out.substr(a.out.find(' '))) << "one version: " << c.out << a.out;
}

// autumnc says how the program lowered and what it wrote.
TEST(Cli, AutumncSaysWhatItWrote) {
  const fs::path dir = fs::temp_directory_path() / "autumn_cli_test_wrote";
  fs::remove_all(dir);
  Result r = autumn::testing::run_cli(golden("stale_occupancy.au") + " -o " + dir.string(), false, "", AUTUMNC_CLI);
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("stale_occupancy.au: specialised, "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("wrote " + (dir / "stale_occupancy.cpp").string() + "\n"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir / "stale_occupancy.cpp"));
  // Its header says how to regenerate it: with autumnc, from the program it came from.
  const std::string head = autumn::testing::read_text(dir / "stale_occupancy.cpp").substr(0, 400);
  EXPECT_NE(head.find("regenerate it with\n// `autumnc " + golden("stale_occupancy.au") + "`"), std::string::npos) << head;
  fs::remove_all(dir);
}

// autumnc --dump-ir STAGE prints the IR after that stage (and writes nothing);
// a stage that does not exist is a usage error naming the stages; a program
// the lowering embeds has no IR, and says why.
TEST(Cli, AutumncDumpsTheIrAfterAStage) {
  const fs::path dir = fs::temp_directory_path() / "autumn_cli_test_dump_ir";
  fs::remove_all(dir);
  const std::string prog = golden("stale_occupancy.au");
  Result r = autumn::testing::run_cli(prog + " --dump-ir remove_dead_names -o " + dir.string(), true, "", AUTUMNC_CLI);
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(r.out.rfind("module stale_occupancy\n", 0), 0u) << r.out.substr(0, 200);
  EXPECT_NE(r.out.find("fn step (step)"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir)) << "nothing is written";
  Result bad = autumn::testing::run_cli(prog + " --dump-ir nonsense", false, "", AUTUMNC_CLI);
  EXPECT_EQ(bad.status, 2) << bad.out;
  EXPECT_NE(bad.out.find("spare_short_loops"), std::string::npos) << bad.out;
  const std::string embedded = (autumn::testing::source_dir() / "tests/lowering/construct_own_class.au").string();
  Result none = autumn::testing::run_cli(embedded + " --dump-ir specialise", false, "", AUTUMNC_CLI);
  EXPECT_EQ(none.status, 1) << none.out;
  EXPECT_NE(none.out.find("not specialised ("), std::string::npos) << none.out;
  EXPECT_NE(none.out.find("): it has no lowering IR"), std::string::npos) << none.out;
}

// Under an address-space limit the interpreter's stack (1 GiB reserved, not used)
// is taken smaller: a small program still runs, rather than "out of memory".
TEST(Cli, ALimitedAddressSpaceStillRunsTheInterpreter) {
  const std::string cmd = "ulimit -v 600000 && " + std::string(AUTUMN_CLI) + " run " + golden("stale_occupancy.au") +
                          " --engine interp --steps 2 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int st = pclose(p);
  EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << out;
  EXPECT_NE(out.find("# frame 2"), std::string::npos) << out;
}

// --- robustness: bad programs among good ones, limits, nesting (runtime/limits.hpp)


// A folder holding a good program and three that used to crash or stop a run. Each test
// names its own folder: ctest runs tests in parallel, and one test must not edit another's.
fs::path mixed_folder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("autumn_cli_mixed_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::copy_file(golden("stale_occupancy.au"), dir / "a_good.au");
  std::ofstream(dir / "b_unclosed.au") << "(program (= x 1)";
  std::ofstream(dir / "c_recursion.au") << "(program (= GRID_SIZE 4) (= f (fn (n) (f n))) (= x (initnext (f 1) 2)))";
  std::string deep = "(program (= x ";
  for (int i = 0; i < 20000; ++i) deep += "(+ 1 ";
  deep += "1" + std::string(20000, ')') + "))";
  std::ofstream(dir / "d_deep.au") << deep;
  return dir;
}

TEST(Cli, SurveyReportsBadProgramsInTheirRowsAndGoesOn) {
  Result r = run("survey " + mixed_folder("survey").string() + " --steps 5");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("b_unclosed.au:1:1: error: unclosed '('"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("c_recursion.au:1:39: runtime error: initialising 'x': call depth limit exceeded"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("d_deep.au:1:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("nested too deeply"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("4 programs, 5 steps, 6 frames, 3 failed"), std::string::npos) << r.out;
}

TEST(Cli, SurveyWithAnUnwritableCacheStillRunsTheProgram) {
  // The module cache cannot be created: the compiled engine falls back (to a
  // temporary cache or the interpreter) and the row is still a run, not a failure.
  const fs::path dir = fs::temp_directory_path() / "autumn_cli_noengine";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "p.au") << "(program (= GRID_SIZE 3) (= x (initnext 1 (+ x 1))))";
  Result r = autumn::testing::run_cli("survey " + dir.string() + " --steps 2 --engine compiled", false,
                                      "AUTUMN_CACHE_DIR=/proc/autumn-no-cache");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("1 programs, 2 steps, 3 frames, 0 failed"), std::string::npos) << r.out;
}

TEST(Cli, DifftestGoesOnPastBadPrograms) {
  const fs::path dir = mixed_folder("difftest");
  fs::remove(dir / "d_deep.au");
  Result r = run("difftest " + dir.string() + " --seeds 1 --steps 3");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("FAILED " + (dir / "b_unclosed.au").string() + ": the program does not load"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("3 programs, 2 episodes: 1 ran every step, 1 ended in the same runtime error"), std::string::npos) << r.out;
}

// A program that crashes the process testing it (here: nesting within the
// parser's limit, under a stack too small for it) is that program's failure, not
// the run's: each program is tested in a child process (harness/isolate.hpp).
// The interpreter against itself (--engine interp): no compiler runs under the
// small stack.
TEST(Cli, DifftestGoesOnPastACrashingProgram) {
  const fs::path dir = fs::temp_directory_path() / "autumn_cli_crash_difftest";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "a_good.au") << "(program (= GRID_SIZE 4) (object P (Cell 0 0 \"red\")) "
                                      "(= p (initnext (P (Position 1 1)) (prev p))) (on left (= p (moveLeft p))))";
  std::string deep = "(program (= GRID_SIZE 4) (= x (initnext ";
  for (int i = 0; i < 990; ++i) deep += "(+ 1 ";
  deep += "1" + std::string(990, ')') + " 2)))";
  std::ofstream(dir / "b_deep.au") << deep;
  std::ofstream(dir / "c_good.au") << "(program (= GRID_SIZE 3) (= x (initnext 1 (+ (prev x) 1))))";
  Result plain = run("difftest " + (dir / "b_deep.au").string() + " --seeds 1 --steps 3 --engine interp");
  ASSERT_EQ(plain.status, 0) << "with the usual stack the deep program must run: " << plain.out.substr(0, 400);
  // difftest DIR: a_good, b_deep (crashes), c_good (run after the crash).
  Result r = autumn::testing::run_cli("difftest " + dir.string() + " --seeds 1 --steps 3 --engine interp", false,
                                      "ulimit -s 160 &&");
  EXPECT_EQ(r.status, 1) << r.out.substr(0, 2000);
  // Killed by SIGSEGV in the release tree; ASan reports the overflow and aborts.
  EXPECT_NE(r.out.find("CRASHED " + (dir / "b_deep.au").string() + ": the process testing it "),
            std::string::npos)
      << r.out.substr(0, 2000);
  EXPECT_NE(r.out.find("3 programs, 2 episodes: 2 ran every step"), std::string::npos) << r.out.substr(0, 2000);
  EXPECT_NE(r.out.find("1 programs failed"), std::string::npos) << r.out.substr(0, 2000);
}

TEST(Cli, LimitsFlag) {
  Result bad = run("run " + golden("stale_occupancy.au") + " --limits cells=0");
  EXPECT_EQ(bad.status, 2) << bad.out;
  EXPECT_NE(bad.out.find("--limits: 'cells=0': N must be a positive integer"), std::string::npos) << bad.out;
  const std::string prog = (autumn::testing::source_dir() / "tests/limits/list_length.au").string();
  Result r = run("run " + prog + " --steps 12 --limits list-length=1000");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("list_length.au:8:28: runtime error: list too long: 1024 elements, the limit is 1000"),
            std::string::npos)
      << r.out;
  Result raised = run("run " + prog + " --steps 12 --limits list-length=5000");
  EXPECT_EQ(raised.status, 0) << raised.out;
}

TEST(Cli, DeeplyNestedTriggerIsALocatedError) {
  std::string trigger;
  for (int i = 0; i < 3000; ++i) trigger += "(! ";
  trigger += "true" + std::string(3000, ')');
  Result r = run("run " + golden("stale_occupancy.au") + " --trigger '" + trigger + "'");
  EXPECT_EQ(r.status, 1) << r.out.substr(0, 500);
  EXPECT_NE(r.out.find("<trigger>:1:"), std::string::npos) << r.out.substr(0, 500);
  EXPECT_NE(r.out.find("nested too deeply"), std::string::npos) << r.out.substr(0, 500);
}

TEST(Cli, AutumncRefusesABadGridSizeAtCompileTime) {
  const fs::path p = fs::temp_directory_path() / "autumnc_grid_zero.au";
  std::ofstream(p) << "(program\n  (= GRID_SIZE 0))\n";
  Result r = autumn::testing::run_cli(p.string() + " -o " + (fs::temp_directory_path() / "autumnc_out").string(), false, "",
                                      AUTUMNC_CLI);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find(p.string() + ":2:3: error: GRID_SIZE must be a number from 1 to 4096, got 0"),
            std::string::npos)
      << r.out;
}

// A file that cannot be read has no line: "file: error: ...", not "file:0:0:";
// for autumnc, as for autumn's single-program commands, it is a usage error (2).
// A multi-program command (bench) reports it in its row and exits 1.
TEST(Cli, UnreadableProgramIsAnErrorWithoutALine) {
  const std::string out = " -o " + (fs::temp_directory_path() / "autumnc_out").string();
  Result missing = autumn::testing::run_cli("/nonexistent/prog.au" + out, false, "", AUTUMNC_CLI);
  EXPECT_EQ(missing.status, 2) << missing.out;
  EXPECT_NE(missing.out.find("/nonexistent/prog.au: error: cannot open file"), std::string::npos) << missing.out;
  const std::string dir = fs::temp_directory_path().string();
  Result folder = autumn::testing::run_cli(dir + out, false, "", AUTUMNC_CLI);
  EXPECT_EQ(folder.status, 2) << folder.out;
  EXPECT_NE(folder.out.find(dir + ": error: is a folder, not a program file"), std::string::npos) << folder.out;
  Result bench = run("bench /nonexistent/prog.au --steps 1");
  EXPECT_EQ(bench.status, 1) << bench.out;
  EXPECT_NE(bench.out.find("/nonexistent/prog.au: error: cannot open file"), std::string::npos) << bench.out;
}

// bench's time cap: past it, both engines are timed over the same prefix of the
// actions and the row says so (a program whose state grows each step can take
// the interpreter minutes a replay); the row still counts in the medians.
TEST(Cli, BenchTimeCapTimesBothEnginesOverTheSamePrefix) {
  const std::string prog = autumn::testing::source_dir().string() + "/programs/sokoban.au";
  Result r = run("bench " + prog + " --steps 100000 --time-cap 0.02 --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto report = nlohmann::json::parse(r.out.substr(r.out.find('{')));
  const auto& row = report.at("rows").at(0);
  ASSERT_TRUE(row.contains("note")) << row.dump();
  const size_t steps = row.at("steps").get<size_t>();
  EXPECT_NE(row.at("note").get<std::string>().find("timed over the first " + std::to_string(steps) + " of 100000 steps"),
            std::string::npos)
      << row.dump();
  EXPECT_LT(steps, 100000u);
  EXPECT_GT(steps, 0u);
  EXPECT_TRUE(row.at("interp").at("ok").get<bool>()) << row.dump();
  EXPECT_TRUE(row.at("compiled").at("ok").get<bool>()) << row.dump();
  EXPECT_GT(row.at("ratio").get<double>(), 0) << row.dump();
  EXPECT_EQ(report.at("time_cap").get<double>(), 0.02);
  Result table = run("bench " + prog + " --steps 100000 --time-cap 0.02");
  EXPECT_EQ(table.status, 0) << table.out;
  EXPECT_NE(table.out.find("timed over the first"), std::string::npos) << table.out;
}

// Numeric options share one rule (harness/cli/number_options.hpp): CLI11 alone
// would take a negative seed as 2^64 - 5 and a negative bench --steps as 2^64 - 3.
TEST(Cli, NumericOptionsRejectWhatTheyWouldWrap) {
  const std::string prog = golden("stale_occupancy.au");
  struct Case {
    std::string args, message;
  };
  const Case cases[] = {
      {"run " + prog + " --seed -5", "--seed: -5 is not a whole number from 0 to 18446744073709551615"},
      {"run " + prog + " --seed 18446744073709551616", "--seed: 18446744073709551616 is not a whole number from 0"},
      {"run " + prog + " --seed 0x10", "--seed: 0x10 is not a whole number"},
      {"run " + prog + " --steps -1", "--steps: -1 is not a whole number from 0 to 2147483647"},
      {"bench " + prog + " --steps -3", "--steps: -3 is not a whole number from 0 to 2147483647"},
      {"bench " + prog + " --time-cap -1", "--time-cap: -1 is not a number of at least 0"},
      {"difftest " + prog + " --steps -3", "--steps: -3 is not a whole number from 0 to 2147483647"},
      {"solve " + prog + " --threads 100000", "--threads: 100000 is not a whole number from 0 to 1024"},
      {"solve " + prog + " --nodes 0", "--nodes: 0 is not a whole number from 1 to 18446744073709551615"},
      {"solve " + prog + " --time-limit -1", "--time-limit: -1 is not a number of at least 0"},
  };
  for (const Case& c : cases) {
    Result r = run(c.args);
    EXPECT_EQ(r.status, 2) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find(c.message), std::string::npos) << c.args << "\n" << r.out;
    EXPECT_EQ(r.out.find("1797693134862315708"), std::string::npos) << "no DBL_MAX in full: " << r.out;
  }
  Result ok = run("run " + prog + " --seed 18446744073709551615 --steps 1");
  EXPECT_EQ(ok.status, 0) << ok.out;
}

}  // namespace
}  // namespace cli_test
