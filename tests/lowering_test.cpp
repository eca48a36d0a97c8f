// The lowering: what specialises, and that the specialised code does what the
// interpreter does.
//
// tests/lowering/*.au are small programs, each pinning down one construct of
// compiler/lower, with an inline expectation:
//   ; expect: static              specialised, no dynamic site
//   ; expect: dynamic N           specialised, N dynamic sites
//   ; expect: embedded "TEXT"     not specialised, the reason containing TEXT
// and optionally "; actions: ..." run after reset. Each runs on both engines
// (the given actions, then seeds under a random policy): frames, trigger,
// coverage and error messages must agree.
//
// Every program of programs/ and of the conformance corpus must specialise with
// no dynamic site (docs/design.md lists what would not).
//
// IrPasses builds IR by hand and checks each pass's decision.
#include <gtest/gtest.h>

#include "compiler/analyse/program.hpp"
#include "compiler/lower/lower.hpp"
#include "compiler/lower/module.hpp"
#include "compiler/lower/passes.hpp"
#include "harness/difftest.hpp"
#include "harness/engine.hpp"
#include "harness/transcript.hpp"
#include "test_support.hpp"

namespace autumn {
namespace {

using testing::files_in;
using testing::header;
using testing::read_text;
using testing::source_dir;

std::string name_of(const ::testing::TestParamInfo<std::filesystem::path>& info) {
  std::string n = info.param.stem().string();
  for (char& c : n)
    if (!isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
}

// Runs the actions on both engines from `seed`; the transcripts (frames, and the
// error that ends an episode) must be identical.
void expect_same_transcripts(const std::shared_ptr<const Program>& program, const std::vector<Action>& actions,
                             uint64_t seed) {
  std::string why;
  auto interp = make_environment("interp", program, &why);
  auto compiled = make_environment("compiled", program, &why);
  ASSERT_TRUE(interp && compiled) << why;
  Transcript a = run_transcript(*interp, seed, actions, true);
  Transcript b = run_transcript(*compiled, seed, actions, true);
  EXPECT_EQ(a.text, b.text) << program->file.name << " seed " << seed;
}

class LoweringFile : public ::testing::TestWithParam<std::filesystem::path> {};

TEST_P(LoweringFile, SpecialisesAsExpectedAndAgreesWithTheInterpreter) {
  const std::string path = GetParam().string();
  const std::string text = read_text(GetParam());
  const std::string expect = header(text, "expect");
  ASSERT_FALSE(expect.empty()) << path << " has no '; expect:' header";
  auto program = load_program(SourceFile{path, text});
  Lowered l = lower_program(*program, "t");
  if (expect == "static") {
    EXPECT_TRUE(l.ok) << l.reason;
    EXPECT_TRUE(l.dynamic_sites.empty()) << l.dynamic_sites.front();
  } else if (expect.rfind("dynamic ", 0) == 0) {
    EXPECT_TRUE(l.ok) << l.reason;
    std::string sites;
    for (const std::string& d : l.dynamic_sites) sites += "\n  " + d;
    EXPECT_EQ(l.dynamic_sites.size(), std::stoul(expect.substr(8))) << path << sites;
  } else if (expect.rfind("embedded ", 0) == 0) {
    const std::string reason = expect.substr(10, expect.size() - 11);  // between the quotes
    EXPECT_FALSE(l.ok);
    EXPECT_NE(l.reason.find(reason), std::string::npos) << l.reason;
  } else {
    FAIL() << "unknown expectation: " << expect;
  }
  std::string why;
  auto actions = parse_action_list(header(text, "actions"), &why);
  ASSERT_TRUE(actions) << why;
  expect_same_transcripts(program, *actions, 3);
  // An embedded module runs the interpreter itself: two episodes check the
  // embedding (construct_own_class recurses to the call-depth limit every step).
  DiffOptions o;
  o.seeds = l.ok ? 6 : 2;
  o.steps = l.ok ? 60 : 30;
  DiffResult r = diff_engines(program, o);
  EXPECT_EQ(r.divergence, "");
}

INSTANTIATE_TEST_SUITE_P(Files, LoweringFile, ::testing::ValuesIn(files_in(source_dir() / "tests/lowering", ".au")),
                         name_of);

std::vector<std::filesystem::path> corpus() {
  auto out = files_in(source_dir() / "programs", ".au");
  for (const auto& p : files_in(testing::shared_dir() / "conformance/programs", ".sexp")) out.push_back(p);
  return out;
}

class CorpusProgram : public ::testing::TestWithParam<std::filesystem::path> {};

TEST_P(CorpusProgram, SpecialisesWithNoDynamicSite) {
  auto program = load_program_file(GetParam().string());
  Lowered l = lower_program(*program, "t");
  EXPECT_TRUE(l.ok) << l.reason;
  for (const std::string& d : l.dynamic_sites) ADD_FAILURE() << d;
}

INSTANTIATE_TEST_SUITE_P(Programs, CorpusProgram, ::testing::ValuesIn(corpus()), name_of);

// ---------------------------------------------------------------------------
// IrPasses: each pass on IR built by hand.

// A module with one function and a builder for its statements.
struct IrFixture {
  lower::Module m;
  lower::ir::Function* f;
  lower::TypeP list_t;
  IrFixture() {
    m.functions.push_back(std::make_unique<lower::ir::Function>());
    f = m.functions.back().get();
    f->name = "step";
    f->kind = lower::ir::Function::Step;
    list_t = m.types.list(m.types.int_());
    m.slots.push_back(lower::ir::Slot{"g_xs", list_t, lower::ir::Slot::Value, 1, true});
  }
  lower::ir::Node* node(lower::ir::Op op, lower::TypeP t, std::vector<lower::ir::Node*> a = {}) {
    lower::ir::Node& n = m.arena.nodes.emplace_back();
    n.op = op;
    n.type = t;
    n.a = std::move(a);
    return &n;
  }
  lower::ir::Node* global() {
    lower::ir::Node* n = node(lower::ir::Op::Global, list_t);
    n->slot = 0;
    return n;
  }
  lower::ir::Var* var(lower::TypeP t, bool mut) {
    lower::ir::Var& v = m.arena.vars.emplace_back();
    v.id = static_cast<int>(m.arena.vars.size());
    v.type = t;
    v.mut = mut;
    return &v;
  }
  lower::ir::Node* use(lower::ir::Var* v) {
    lower::ir::Node* n = node(lower::ir::Op::Local, v->type);
    n->var = v;
    return n;
  }
  lower::ir::Stmt* stmt(lower::ir::Block& b, lower::ir::SK k, lower::ir::Var* v = nullptr, lower::ir::Node* a = nullptr,
                        lower::ir::Node* bn = nullptr) {
    lower::ir::Stmt& s = m.arena.stmts.emplace_back();
    s.k = k;
    s.var = v;
    s.a = a;
    s.b = bn;
    b.push_back(&s);
    return &s;
  }
  lower::ir::Node* size_of(lower::ir::Var* v) { return node(lower::ir::Op::Size, m.types.int_(), {use(v)}); }
};

TEST(IrPasses, ReferenceKeptWhenNoStoreIntervenes) {
  IrFixture x;
  auto* t = x.var(x.list_t, false);
  x.stmt(x.f->body, lower::ir::SK::Bind, t, x.global());
  x.stmt(x.f->body, lower::ir::SK::Eval, nullptr, x.size_of(t));
  x.stmt(x.f->body, lower::ir::SK::Set, nullptr, x.global(), x.node(lower::ir::Op::MakeList, x.list_t));
  lower::settle_references(x.m);
  EXPECT_TRUE(t->is_ref);
}

TEST(IrPasses, CopyWhenAStoreComesBeforeALaterUse) {
  IrFixture x;
  auto* t = x.var(x.list_t, false);
  x.stmt(x.f->body, lower::ir::SK::Bind, t, x.global());
  x.stmt(x.f->body, lower::ir::SK::Set, nullptr, x.global(), x.node(lower::ir::Op::MakeList, x.list_t));
  x.stmt(x.f->body, lower::ir::SK::Eval, nullptr, x.size_of(t));
  lower::settle_references(x.m);
  EXPECT_FALSE(t->is_ref);
}

TEST(IrPasses, CopyWhenALoopRepeatsAStoreBeforeAUse) {
  IrFixture x;
  auto* t = x.var(x.list_t, false);
  x.stmt(x.f->body, lower::ir::SK::Bind, t, x.global());
  auto* loop = x.stmt(x.f->body, lower::ir::SK::ForRange, x.var(x.m.types.int_(), false),
                      x.node(lower::ir::Op::Lit, x.m.types.int_()), x.node(lower::ir::Op::Lit, x.m.types.int_()));
  x.stmt(loop->body, lower::ir::SK::Eval, nullptr, x.size_of(t));
  x.stmt(loop->body, lower::ir::SK::Set, nullptr, x.global(), x.node(lower::ir::Op::MakeList, x.list_t));
  lower::settle_references(x.m);
  EXPECT_FALSE(t->is_ref);
}

TEST(IrPasses, LastUseOfAListMovesIt) {
  IrFixture x;
  auto* v = x.var(x.list_t, true);
  x.stmt(x.f->body, lower::ir::SK::Decl, v);
  auto* store = x.stmt(x.f->body, lower::ir::SK::Set, nullptr, x.global(), x.use(v));
  lower::move_last_uses(x.m);
  EXPECT_TRUE(store->move_value);
  IrFixture y;
  auto* w = y.var(y.list_t, true);
  y.stmt(y.f->body, lower::ir::SK::Decl, w);
  auto* store2 = y.stmt(y.f->body, lower::ir::SK::Set, nullptr, y.global(), y.use(w));
  y.stmt(y.f->body, lower::ir::SK::Eval, nullptr, y.size_of(w));
  lower::move_last_uses(y.m);
  EXPECT_FALSE(store2->move_value) << "used after the store: not moved";
}

TEST(IrPasses, ListsThatStayInTheirBlockReuseStorage) {
  IrFixture x;
  auto* kept = x.var(x.list_t, true);
  auto* escapes = x.var(x.list_t, true);
  x.stmt(x.f->body, lower::ir::SK::Decl, kept);
  x.stmt(x.f->body, lower::ir::SK::Push, nullptr, x.use(kept), x.node(lower::ir::Op::Lit, x.m.types.int_()));
  x.stmt(x.f->body, lower::ir::SK::Eval, nullptr, x.size_of(kept));
  x.stmt(x.f->body, lower::ir::SK::Decl, escapes);
  x.stmt(x.f->body, lower::ir::SK::Set, nullptr, x.global(), x.use(escapes));  // copied into the global
  x.stmt(x.f->body, lower::ir::SK::Eval, nullptr, x.size_of(escapes));
  lower::move_last_uses(x.m);
  lower::reuse_buffers(x.m);
  EXPECT_TRUE(kept->scratch);
  EXPECT_FALSE(escapes->scratch);
}

// A list filled by two pushes right before its loop is walked uncharged; one
// filled in a loop, or by a call, or a long literal range, keeps its charge.
TEST(IrPasses, ShortLoopsAreNotCharged) {
  using lower::ir::SK;
  using lower::ir::Op;
  IrFixture x;
  auto lit = [&](int64_t v) {
    auto* n = x.node(Op::Lit, x.m.types.int_());
    n->imm = v;
    return n;
  };
  auto* two = x.var(x.list_t, true);
  x.stmt(x.f->body, SK::Decl, two);
  x.stmt(x.f->body, SK::Push, nullptr, x.use(two), lit(1));
  x.stmt(x.f->body, SK::Push, nullptr, x.use(two), lit(2));
  auto* short_loop = x.stmt(x.f->body, SK::ForEach, x.var(x.m.types.int_(), false), x.use(two));
  auto* many = x.var(x.list_t, true);
  x.stmt(x.f->body, SK::Decl, many);
  auto* fill = x.stmt(x.f->body, SK::ForRange, x.var(x.m.types.int_(), false), lit(0), x.size_of(two));
  x.stmt(fill->body, SK::Push, nullptr, x.use(many), lit(3));
  auto* filled_in_loop = x.stmt(x.f->body, SK::ForEach, x.var(x.m.types.int_(), false), x.use(many));
  auto* read = x.var(x.list_t, true);
  x.stmt(x.f->body, SK::Decl, read);
  x.stmt(x.f->body, SK::Eval, nullptr, x.node(Op::Call, x.m.types.int_(), {x.use(read)}));  // a call may fill it
  auto* after_call = x.stmt(x.f->body, SK::ForEach, x.var(x.m.types.int_(), false), x.use(read));
  auto* short_range = x.stmt(x.f->body, SK::ForRange, x.var(x.m.types.int_(), false), lit(0), lit(16));
  auto* long_range = x.stmt(x.f->body, SK::ForRange, x.var(x.m.types.int_(), false), lit(0), lit(17));
  auto* global_loop = x.stmt(x.f->body, SK::ForEach, x.var(x.m.types.int_(), false), x.global());
  lower::spare_short_loops(x.m);
  EXPECT_FALSE(short_loop->charged);
  EXPECT_TRUE(filled_in_loop->charged);
  EXPECT_TRUE(fill->charged) << "its bound is a list's size";
  EXPECT_TRUE(after_call->charged);
  EXPECT_FALSE(short_range->charged);
  EXPECT_TRUE(long_range->charged);
  EXPECT_TRUE(global_loop->charged);
}

TEST(IrPasses, UnusedPureNamesAreRemoved) {
  IrFixture x;
  auto* unused = x.var(x.list_t, false);
  auto* used = x.var(x.list_t, false);
  x.stmt(x.f->body, lower::ir::SK::Let, unused, x.node(lower::ir::Op::MakeList, x.list_t));
  x.stmt(x.f->body, lower::ir::SK::Let, used, x.node(lower::ir::Op::MakeList, x.list_t));
  x.stmt(x.f->body, lower::ir::SK::Eval, nullptr, x.size_of(used));
  lower::remove_dead_names(x.m);
  ASSERT_EQ(x.f->body.size(), 2u);
  EXPECT_EQ(x.f->body[0]->var, used);
}

TEST(IrPasses, AReferenceToALocalIsTheLocal) {
  IrFixture x;
  auto* local = x.var(x.list_t, true);
  auto* ref = x.var(x.list_t, false);
  x.stmt(x.f->body, lower::ir::SK::Decl, local);
  x.stmt(x.f->body, lower::ir::SK::Bind, ref, x.use(local));
  lower::ir::Node* read = x.size_of(ref);
  x.stmt(x.f->body, lower::ir::SK::Eval, nullptr, read);
  lower::settle_references(x.m);
  lower::resolve_aliases(x.m);
  EXPECT_EQ(read->a[0]->var, local);
}

}  // namespace
}  // namespace autumn
