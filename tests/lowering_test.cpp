// The lowering: what specialises, and that the specialised code does what the
// interpreter does.
//
// tests/lowering/*.au are small programs, each pinning down one construct of
// compiler/lower, with an inline expectation:
//   ; expect: static              specialised, no dynamic site
//   ; expect: dynamic N           specialised, N dynamic sites
//   ; expect: embedded "TEXT"     not specialised, the reason containing TEXT
// and optionally "; actions: ..." run after reset, and "; random-limits: ..."
// (the --limits syntax) for the random episodes. Each runs on both engines
// (the given actions at the default limits, then seeds under a random policy):
// frames, trigger, coverage and error messages must agree.
//
// Every program of programs/ and of the conformance corpus must specialise with
// no dynamic site (docs/design.md lists what would not).
//
// IrPasses builds IR by hand and checks each pass's decision; IrBuilder,
// ErrorSites and ScopeChain check the specialiser's collaborators alone.
#include <gtest/gtest.h>

#include <cstdlib>
#include <functional>
#include <fstream>

#include "compiler/analyse/program.hpp"
#include "compiler/lower/error_sites.hpp"
#include "compiler/lower/ir_builder.hpp"
#include "compiler/lower/scope_chain.hpp"
#include "compiler/lower/ir_print.hpp"
#include "compiler/lower/ir_verify.hpp"
#include "compiler/lower/lower.hpp"
#include "compiler/lower/module.hpp"
#include "compiler/lower/passes.hpp"
#include "harness/difftest.hpp"
#include "harness/engine.hpp"
#include "harness/transcript.hpp"
#include "test_support.hpp"

namespace autumn::lowering_test {
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
  expect_same_transcripts(program, *actions, 3);  // at the default limits
  // An embedded module runs the interpreter itself: two episodes check the
  // embedding. The random episodes run under the file's "; random-limits:"
  // (test_support.hpp), if any.
  DiffOptions o;
  o.seeds = l.ok ? 6 : 2;
  o.steps = l.ok ? 60 : 8;
  o.limits = testing::random_limits(text, GetParam());
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

// A module with one function, built through the specialiser's own IR builder
// (ir_builder.hpp); stmt() appends to any block of it.
struct IrFixture {
  lower::Module m;
  lower::ir::Function* f;
  lower::TypeP list_t;
  lower::IrBuilder b{m, [] { return -1; }};  // no error sites: loops keep Stmt's default site
  IrFixture() {
    m.functions.push_back(std::make_unique<lower::ir::Function>());
    f = m.functions.back().get();
    f->name = "step";
    f->kind = lower::ir::Function::Step;
    b.begin_function(f);
    list_t = m.types.list(m.types.int_());
    m.slots.push_back(lower::ir::Slot{"g_xs", list_t, lower::ir::Slot::Value, 1, true});
  }
  lower::ir::Node* node(lower::ir::Op op, lower::TypeP t, std::vector<lower::ir::Node*> a = {}) {
    return b.node(op, t, std::move(a));
  }
  lower::ir::Node* global() { return b.slot(0); }
  lower::ir::Var* var(lower::TypeP t, bool mut) {
    lower::ir::Var* v = b.var(t, "v");
    v->mut = mut;
    return v;
  }
  lower::ir::Node* use(lower::ir::Var* v) { return b.local(v); }
  lower::ir::Stmt* stmt(lower::ir::Block& block, lower::ir::SK k, lower::ir::Var* v = nullptr,
                        lower::ir::Node* a = nullptr, lower::ir::Node* bn = nullptr) {
    lower::ir::Stmt* s = nullptr;
    b.in_block(block, [&] { s = b.emit(k); });
    s->var = v;
    s->a = a;
    s->b = bn;
    return s;
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

// addObj's copy of a list at its last use (a loop pushing each element onto a
// list declared empty just before) takes the list whole; not where the list
// is read again, nor where a loop around repeats the copy, nor where the loop
// pushes anything but the element.
TEST(IrPasses, ALoopCopyingADyingListMovesItWhole) {
  using lower::ir::SK;
  enum Shape { kLast, kReadAfter, kInALoop, kPushesOther };
  auto copy_loop = [](Shape shape) {
    IrFixture x;
    auto* from = x.var(x.list_t, true);
    auto* out = x.var(x.list_t, true);
    x.stmt(x.f->body, SK::Decl, from);
    x.stmt(x.f->body, SK::Push, nullptr, x.use(from), x.node(lower::ir::Op::Lit, x.m.types.int_()));
    lower::ir::Block* at = &x.f->body;
    if (shape == kInALoop)
      at = &x.stmt(x.f->body, SK::ForRange, x.var(x.m.types.int_(), false), x.node(lower::ir::Op::Lit, x.m.types.int_()),
                   x.node(lower::ir::Op::Lit, x.m.types.int_()))->body;
    x.stmt(*at, SK::Decl, out);
    auto* elem = x.var(x.m.types.int_(), false);
    auto* loop = x.stmt(*at, SK::ForEach, elem, x.use(from));
    x.stmt(loop->body, SK::Push, nullptr, x.use(out),
           shape == kPushesOther ? x.node(lower::ir::Op::Lit, x.m.types.int_()) : x.use(elem));
    x.stmt(*at, SK::Set, nullptr, x.global(), x.use(out));
    if (shape == kReadAfter) x.stmt(x.f->body, SK::Eval, nullptr, x.size_of(from));
    lower::move_last_uses(x.m);
    return loop->move_value;
  };
  EXPECT_TRUE(copy_loop(kLast));
  EXPECT_FALSE(copy_loop(kReadAfter)) << "read after the copy";
  EXPECT_FALSE(copy_loop(kInALoop)) << "copied again by the next iteration";
  EXPECT_FALSE(copy_loop(kPushesOther)) << "the loop pushes something else";
}

// A loop whose body charges as it runs (a kept element's cells, a loop inside)
// counts in a local; not one that calls a function charging the core, returns
// from inside, or charges nothing; loops inside a marked one use its local.
TEST(IrPasses, LoopsChargingAsTheyRunKeepTheCountsLocal) {
  using lower::ir::SK;
  enum Body { kChargesBuilt, kInnerLoop, kCallsCharging, kReturns, kNothing };
  auto loop_with = [](Body body) {
    IrFixture x;
    auto* xs = x.var(x.list_t, true);
    x.stmt(x.f->body, SK::Decl, xs);
    auto* loop = x.stmt(x.f->body, SK::ForEach, x.var(x.m.types.int_(), false), x.use(xs));
    lower::ir::Stmt* inner = nullptr;
    switch (body) {
      case kChargesBuilt:
        x.stmt(loop->body, SK::Eval, nullptr,
               x.b.call(lower::ir::Helper::ChargeBuilt, nullptr, {x.node(lower::ir::Op::Lit, x.m.types.int_())}));
        break;
      case kInnerLoop:
        inner = x.stmt(loop->body, SK::ForEach, x.var(x.m.types.int_(), false), x.use(xs));
        break;
      case kCallsCharging: {
        // A second function that charges, called from the loop.
        x.m.functions.push_back(std::make_unique<lower::ir::Function>());
        lower::ir::Function* g = x.m.functions.back().get();
        x.stmt(g->body, SK::ForEach, x.var(x.m.types.int_(), false), x.use(xs));
        lower::ir::Node* call = x.node(lower::ir::Op::FnCall, x.m.types.int_());
        call->index = 1;
        x.stmt(loop->body, SK::Eval, nullptr, call);
        x.stmt(loop->body, SK::Eval, nullptr,
               x.b.call(lower::ir::Helper::ChargeBuilt, nullptr, {x.node(lower::ir::Op::Lit, x.m.types.int_())}));
        break;
      }
      case kReturns:
        x.stmt(loop->body, SK::Eval, nullptr,
               x.b.call(lower::ir::Helper::ChargeBuilt, nullptr, {x.node(lower::ir::Op::Lit, x.m.types.int_())}));
        x.stmt(loop->body, SK::Return);
        break;
      case kNothing: x.stmt(loop->body, SK::Eval, nullptr, x.size_of(xs)); break;
    }
    lower::keep_budgets_local(x.m);
    EXPECT_FALSE(inner && inner->local_budget) << "a loop inside a marked one charges its local";
    return loop->local_budget;
  };
  EXPECT_TRUE(loop_with(kChargesBuilt));
  EXPECT_TRUE(loop_with(kInnerLoop));
  EXPECT_FALSE(loop_with(kCallsCharging)) << "the function charges the core";
  EXPECT_FALSE(loop_with(kReturns)) << "a return would skip giving the counts back";
  EXPECT_FALSE(loop_with(kNothing)) << "nothing to charge";
}

// A loop whose body leads with the click's definition under the click flag
// (clicked on each element) defines it once, before the loop: the leading
// stores of literals or the click's position, not a fresh identity; nothing
// where the loop reads the slot or something else leads the flag's branch.
TEST(IrPasses, ClickDefinedInALoopIsDefinedOnce) {
  using lower::ir::SK;
  using lower::ir::Op;
  enum Shape { kLeads, kReadInLoop, kFreshUid, kNotLeading };
  // The statements moved before the loop (0: none), and what the branch kept.
  auto run = [](Shape shape) {
    IrFixture x;
    const lower::TypeP b = x.m.types.bool_(), pos = x.m.types.pos(), i = x.m.types.int_();
    x.m.slots.push_back(lower::ir::Slot{"d_click", nullptr, lower::ir::Slot::Defined, 2, true});
    x.m.slots.push_back(lower::ir::Slot{"g_click", pos, lower::ir::Slot::Value, 2, true});
    x.m.locations.emplace_back();
    auto* xs = x.var(x.list_t, true);
    x.stmt(x.f->body, SK::Decl, xs);
    auto* loop = x.stmt(x.f->body, SK::ForEach, x.var(i, false), x.use(xs));
    loop->loc = 0;
    x.stmt(loop->body, SK::Decl, x.var(b, true), x.b.lit(b, 0));
    auto* branch = x.stmt(loop->body, SK::If, nullptr, x.b.call(lower::ir::Helper::InputFlag, b, {x.b.lit(i, 0)}));
    if (shape == kNotLeading) x.stmt(branch->body, SK::Eval, nullptr, x.size_of(xs));
    x.stmt(branch->body, SK::Set, nullptr, x.b.slot(1), x.b.lit(b, 1));
    auto* t = x.var(pos, false);
    x.stmt(branch->body, SK::Let, t,
           shape == kFreshUid ? x.b.call(lower::ir::Helper::NewUid, i, {}) : x.b.call(lower::ir::Helper::ClickPos, pos, {}));
    x.stmt(branch->body, SK::Set, nullptr, x.b.slot(2), x.use(t));
    x.stmt(branch->body, SK::Eval, nullptr, x.size_of(xs));
    if (shape == kReadInLoop) x.stmt(loop->body, SK::Eval, nullptr, x.node(Op::Not, b, {x.b.slot(1)}));
    lower::define_click_once(x.m);
    for (const auto& problem : lower::verify_ir(x.m)) ADD_FAILURE() << problem;
    if (x.f->body.size() != 3 || x.f->body[2] != loop) return std::make_pair(size_t{0}, branch->body.size());
    EXPECT_EQ(x.f->body[1]->k, SK::If);
    EXPECT_EQ(x.f->body[1]->a->op, Op::And) << "under the flag, if the list has an element";
    return std::make_pair(x.f->body[1]->body.size(), branch->body.size());
  };
  EXPECT_EQ(run(kLeads), std::make_pair(size_t{3}, size_t{1}));
  EXPECT_EQ(run(kReadInLoop), std::make_pair(size_t{0}, size_t{4})) << "the loop reads the definition";
  EXPECT_EQ(run(kFreshUid), std::make_pair(size_t{1}, size_t{3})) << "only the flag: the identity is made each time";
  EXPECT_EQ(run(kNotLeading), std::make_pair(size_t{0}, size_t{5})) << "something else comes first";
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

// let unused = (list); let used = (list); size(used): the variable read last.
lower::ir::Var* unused_then_used(IrFixture& x) {
  auto* unused = x.var(x.list_t, false);
  auto* used = x.var(x.list_t, false);
  x.stmt(x.f->body, lower::ir::SK::Let, unused, x.node(lower::ir::Op::MakeList, x.list_t));
  x.stmt(x.f->body, lower::ir::SK::Let, used, x.node(lower::ir::Op::MakeList, x.list_t));
  x.stmt(x.f->body, lower::ir::SK::Eval, nullptr, x.size_of(used));
  return used;
}

TEST(IrPasses, UnusedPureNamesAreRemoved) {
  IrFixture x;
  auto* used = unused_then_used(x);
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

// ---------------------------------------------------------------------------
// IrBuilder (ir_builder.hpp): where statements go, dead code, effects.

TEST(IrBuilder, DeadCodeIsBuiltButNotAttachedAndBlocksRestoreTheFlag) {
  lower::Module m;
  m.functions.push_back(std::make_unique<lower::ir::Function>());
  lower::ir::Function* f = m.functions.back().get();
  f->name = "step";
  int locations_asked = 0;
  lower::IrBuilder b(m, [&] { return ++locations_asked; });
  b.begin_function(f);
  EXPECT_TRUE(b.at_function_top());
  lower::TypeP i = m.types.int_();
  lower::ir::Var* x = b.decl(i, b.lit(i, 1), "x");
  lower::ir::Stmt* branch = b.emit(lower::ir::SK::If);
  branch->a = b.node(lower::ir::Op::Lt, m.types.bool_(), {b.local(x), b.lit(i, 3)});
  b.in_block(branch->body, [&] {
    EXPECT_FALSE(b.at_function_top());
    b.kill();  // the branch certainly fails: what follows in it never runs
    b.emit_set(b.local(x), b.lit(i, 2));
    EXPECT_TRUE(b.dead());
  });
  EXPECT_FALSE(b.dead()) << "leaving the branch restores the parent's flag";
  EXPECT_EQ(b.block(), &f->body);
  EXPECT_TRUE(branch->body.empty()) << "the statement after the kill is not attached";
  lower::ir::Stmt* loop = b.emit(lower::ir::SK::ForRange);
  EXPECT_EQ(loop->loc, 1) << "a loop takes the current error site";
  lower::ir::Stmt* detached = b.emit_detached(lower::ir::SK::Comment);
  EXPECT_EQ(f->body.size(), 3u);  // decl, if, for_range
  b.attach(detached);
  EXPECT_EQ(f->body.back(), detached);
  // Writing elsewhere and coming back.
  const lower::IrBuilder::Point here = b.point();
  m.functions.push_back(std::make_unique<lower::ir::Function>());
  b.begin_function(m.functions.back().get());
  b.kill();
  b.restore(here);
  EXPECT_FALSE(b.dead());
  EXPECT_EQ(b.block(), &f->body);
  EXPECT_EQ(locations_asked, 1);
}

TEST(IrBuilder, CountsStateChangingHelpersAndStoresOutsideLocals) {
  lower::Module m;
  m.slots.push_back(lower::ir::Slot{"g_n", m.types.int_(), lower::ir::Slot::Value, 1, true});
  m.functions.push_back(std::make_unique<lower::ir::Function>());
  lower::IrBuilder b(m, [] { return 0; });
  b.begin_function(m.functions.back().get());
  lower::TypeP i = m.types.int_();
  lower::ir::Var* x = b.decl(i, b.lit(i, 0), "x");
  b.emit_set(b.local(x), b.lit(i, 1));
  b.call(lower::ir::Helper::Sqrt, i, {b.lit(i, 4)});
  EXPECT_EQ(b.effects(), 0u) << "a local store and a pure helper change no state";
  b.emit_set(b.slot(0), b.lit(i, 1));
  EXPECT_EQ(b.effects(), 1u);
  b.call(lower::ir::Helper::RngNext, i, {});
  EXPECT_EQ(b.effects(), 2u);
  EXPECT_TRUE(lower::is_const(b.node(lower::ir::Op::MakePos, m.types.pos(), {b.lit(i, 1), b.lit(i, 2)})));
  EXPECT_FALSE(lower::is_const(b.local(x)));
  EXPECT_FALSE(lower::is_stable(b.local(x))) << "x is mutable";
}

// ErrorSites (error_sites.hpp): errors are placed at the construct being lowered
// and at the program's innermost one (stdlib code is reported at the program's call).
TEST(ErrorSites, PlacesAtTheProgramsInnermostConstructAndInternsOnce) {
  lower::Module m;
  lower::ErrorSites sites(m);
  Expr call{ExprKind::Call, SourceLoc{3, 5, SourceId::Program}};
  Expr in_stdlib{ExprKind::Var, SourceLoc{40, 2, SourceId::Stdlib}};
  sites.enter(&call);
  sites.enter(&in_stdlib);
  EXPECT_TRUE(sites.in_program());
  const int first = sites.here();
  ASSERT_EQ(m.locations.size(), 1u);
  EXPECT_EQ(m.locations[0].at.line, 40) << "the construct being evaluated";
  EXPECT_TRUE(m.locations[0].in_program);
  EXPECT_EQ(m.locations[0].program_at.line, 3) << "the program's call into the stdlib";
  EXPECT_EQ(sites.here(), first) << "the same place is one site";
  sites.set_prefix("initialising 'x': ");
  EXPECT_NE(sites.here(), first) << "a prefix makes another site";
  EXPECT_EQ(m.locations.back().prefix, "initialising 'x': ");
  try {
    sites.unsupported("not here");
    ADD_FAILURE() << "unsupported returned";
  } catch (const lower::Unsupported& u) {
    EXPECT_EQ(u.why, "not here");
    EXPECT_EQ(u.loc.line, 3);
    EXPECT_EQ(u.loc.col, 5);
  }
  sites.dynamic_site("two types");
  sites.dynamic_site("two types");
  ASSERT_EQ(m.dynamic_sites.size(), 1u) << "reported once per place and reason";
  EXPECT_EQ(m.dynamic_sites[0].loc.line, 3);
  sites.reset(&in_stdlib);
  EXPECT_FALSE(sites.in_program());
  EXPECT_EQ(&sites.innermost(), &in_stdlib);
}

// ScopeChain (scope_chain.hpp): the scopes a lookup sees, and a trial's swap.
TEST(ScopeChain, PushPopAndReplaceGiveTheVisibleScopes) {
  lower::ir::Block block;
  lower::ScopeChain chain;
  EXPECT_TRUE(chain.empty());
  lower::SScope* outer = chain.push(lower::ScopeKind::Local, &block);
  outer->vars.push_back(lower::Binding{7});
  lower::SScope* inner = chain.push(lower::ScopeKind::Instance, &block);
  EXPECT_EQ(&chain.innermost(), inner);
  EXPECT_TRUE(chain.binds(7));
  EXPECT_FALSE(chain.binds(8));
  lower::SScope capture;
  const lower::ScopeChain::Chain saved = chain.replace({&capture});
  EXPECT_FALSE(chain.binds(7)) << "a cell argument's trial sees its capture scope alone";
  chain.replace(saved);
  EXPECT_TRUE(chain.binds(7));
  chain.pop();
  EXPECT_EQ(&chain.innermost(), outer);
  chain.pop();
  EXPECT_TRUE(chain.empty());
}

// ---------------------------------------------------------------------------
// IrVerify: the verifier (ir_verify.hpp) catches what a broken pass leaves.

// A dead-name pass that forgets to look at uses: it removes every Let, the used
// one too. The verifier names the read that lost its variable.
TEST(IrVerify, CatchesAPassThatRemovesAUsedName) {
  IrFixture x;
  auto* used = unused_then_used(x);
  EXPECT_TRUE(lower::verify_ir(x.m).empty());
  auto broken_dead_names = [](lower::Module& m) {
    for (auto& f : m.functions)
      std::erase_if(f->body, [](const lower::ir::Stmt* s) { return s->k == lower::ir::SK::Let; });
  };
  broken_dead_names(x.m);
  auto problems = lower::verify_ir(x.m);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0], "function step: v" + std::to_string(used->id) + " read out of its scope");
}

// A budget pass that marks every loop: the one that returns from inside and
// the one inside another are caught (each would lose or split the counts).
TEST(IrVerify, CatchesALoopKeepingTheBudgetLocalThatCannotGiveItBack) {
  using lower::ir::SK;
  IrFixture x;
  auto* xs = x.var(x.list_t, true);
  x.stmt(x.f->body, SK::Decl, xs);
  auto* outer = x.stmt(x.f->body, SK::ForEach, x.var(x.m.types.int_(), false), x.use(xs));
  auto* inner = x.stmt(outer->body, SK::ForEach, x.var(x.m.types.int_(), false), x.use(xs));
  x.stmt(inner->body, SK::Return);
  outer->loc = inner->loc = 0;
  x.m.locations.emplace_back();
  EXPECT_TRUE(lower::verify_ir(x.m).empty());
  auto broken_budget_locals = [](lower::Module& m) {
    std::function<void(lower::ir::Block&)> all = [&](lower::ir::Block& b) {
      for (lower::ir::Stmt* s : b) {
        if (s->k == SK::ForEach) s->local_budget = true;
        all(s->body);
      }
    };
    for (auto& f : m.functions) all(f->body);
  };
  broken_budget_locals(x.m);
  const auto problems = lower::verify_ir(x.m);
  std::string all;
  for (const auto& p : problems) all += p + "\n";
  EXPECT_NE(all.find("a loop keeping the budget in a local holds another"), std::string::npos) << all;
  EXPECT_NE(all.find("a loop keeping the budget in a local returns from inside"), std::string::npos) << all;
  EXPECT_EQ(problems.size(), 3u) << all;  // the outer loop twice (holds, returns), the inner once (returns)
}

TEST(IrVerify, CatchesMissingOperandsArityTypesAndSites) {
  IrFixture x;
  auto* v = x.var(x.list_t, false);
  x.stmt(x.f->body, lower::ir::SK::Let, v, x.node(lower::ir::Op::MakeList, x.list_t));
  x.stmt(x.f->body, lower::ir::SK::Eval, nullptr, x.node(lower::ir::Op::Size, x.m.types.int_(), {nullptr}));
  x.stmt(x.f->body, lower::ir::SK::Eval, nullptr, x.node(lower::ir::Op::Add, x.m.types.int_(), {x.size_of(v)}));
  x.stmt(x.f->body, lower::ir::SK::Eval, nullptr, x.node(lower::ir::Op::Size, nullptr, {x.use(v)}));
  x.stmt(x.f->body, lower::ir::SK::Let, v, x.node(lower::ir::Op::MakeList, x.list_t));
  lower::ir::Stmt* loop = x.stmt(x.f->body, lower::ir::SK::ForEach, x.var(x.m.types.int_(), false), x.use(v));
  loop->loc = 7;  // no error sites in the fixture
  lower::ir::Stmt* sw = x.stmt(loop->body, lower::ir::SK::Switch, nullptr, x.size_of(v));
  sw->cases.push_back({0, {}});
  x.stmt(sw->cases[0].second, lower::ir::SK::Break);
  x.stmt(x.f->body, lower::ir::SK::Break);
  const auto problems = lower::verify_ir(x.m);
  const std::string all = [&] {
    std::string s;
    for (const auto& p : problems) s += p + "\n";
    return s;
  }();
  for (const char* want : {"a null operand in a eval", "has 1 operand(s), wants 2", "has no type",
                           "introduced twice (again by let)", "names error site 7, which does not exist",
                           "a break inside a switch", "a break outside a loop"})
    EXPECT_NE(all.find(want), std::string::npos) << want << " not in:\n" << all;
  EXPECT_EQ(problems.size(), 7u) << all;
}

// Every stage of every program we have leaves sound IR: lower_program's own
// verification (its one list of stages), switched on for the test.
TEST(IrVerify, EveryStageOfTheCorpusIsSound) {
  auto files = corpus();
  // The error-path programs too: their lowering stops at failing builtins, wrong
  // argument counts, broken limits (under ASan this is where a read past the
  // arguments shows; tests/runtime_errors/builtin_arity.au).
  for (const char* dir : {"tests/lowering", "tests/runtime_errors", "tests/golden", "tests/limits"})
    for (const auto& f : files_in(source_dir() / dir, ".au")) files.push_back(f);
  const char* before = std::getenv("AUTUMN_VERIFY_IR");
  const std::string saved = before ? before : "";
  setenv("AUTUMN_VERIFY_IR", "1", 1);
  for (const auto& path : files) {
    auto program = load_program_file(path.string());
    EXPECT_NO_THROW(lower_program(*program, "t")) << path.filename();
  }
  if (before) setenv("AUTUMN_VERIFY_IR", saved.c_str(), 1);
  else unsetenv("AUTUMN_VERIFY_IR");
}

// Filetests (tests/ir/STAGE.ir): a program named in the header and the IR
// expected after that stage, so a pass's effect is read as text and a change to
// it shows as a diff. AUTUMN_BLESS=1 rewrites the expectations from the lowering.
class IrFile : public ::testing::TestWithParam<std::filesystem::path> {};

TEST_P(IrFile, IsTheIrAfterItsStage) {
  const std::string text = read_text(GetParam());
  const std::string program_path = header(text, "program"), stage = header(text, "stage");
  ASSERT_FALSE(program_path.empty() || stage.empty()) << "a filetest starts with '; program: PATH' and '; stage: NAME'";
  const std::filesystem::path program_file = source_dir() / program_path;
  // Named as in the header (the IR's comments quote it): the same text on any checkout.
  auto program = load_program(SourceFile{program_path, read_text(program_file)});
  LowerOptions o;
  o.dump_ir_after = stage;
  const Lowered l = lower_program(*program, program_file.stem().string(), o);
  ASSERT_TRUE(l.ok) << l.reason;
  ASSERT_FALSE(l.ir.empty()) << "no stage named '" << stage << "'";
  const std::string head = "; program: " + program_path + "\n; stage: " + stage + "\n";
  if (std::getenv("AUTUMN_BLESS")) {
    std::ofstream(GetParam(), std::ios::binary) << head << l.ir;
    return;
  }
  EXPECT_EQ(text.substr(std::min(text.size(), head.size())), l.ir)
      << GetParam().filename() << " (AUTUMN_BLESS=1 rewrites it)";
}

INSTANTIATE_TEST_SUITE_P(Files, IrFile, ::testing::ValuesIn(files_in(source_dir() / "tests/ir", ".ir")), name_of);

TEST(IrText, NamesFunctionsStatementsAndTypes) {
  auto program = load_program_file((source_dir() / "programs/sokoban.au").string());
  LowerOptions o;
  o.dump_ir_after = "spare_short_loops";
  Lowered l = lower_program(*program, "sokoban", o);
  ASSERT_TRUE(l.ok) << l.reason;
  for (const char* want : {"module sokoban\n", "\n#0 fn start (start)\n", "fn step (step)", "  for_each v",
                           ": list<pos>", "make_obj Crate(", "set global g_crates_"})
    EXPECT_NE(l.ir.find(want), std::string::npos) << want;
  EXPECT_EQ(lowering_stages().front(), "specialise");
  EXPECT_EQ(lowering_stages().size(), 10u);
  o.dump_ir_after = "specialise";
  EXPECT_NE(lower_program(*program, "sokoban", o).ir, l.ir) << "the passes change the IR";
}

}  // namespace
}  // namespace autumn::lowering_test
