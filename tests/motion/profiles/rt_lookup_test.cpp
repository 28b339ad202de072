// Every lookup the loop makes into the profiles allocates nothing and cannot throw: global operator
// new is replaced in this executable (alloc_counter.cpp) and counts calls made while the lookups
// run, and each lookup is checked to be noexcept at compile time.
#include <gtest/gtest.h>

#include <memory>

#include "alloc_counter.hpp"
#include "loom/motion/profile_set.hpp"
#include "loom/motion/profile_slot.hpp"

using namespace loom::motion;

namespace {

// Allocations made by f on this thread.
template <class F>
std::size_t allocations_in(F&& f) {
  loom::test::reset_allocations();
  loom::test::count_allocations(true);
  f();
  loom::test::count_allocations(false);
  return loom::test::allocations();
}

ProfileSpec spec(Interp interp, Precision prec) {
  ProfileSpec s;
  s.crank_law.kind = CrankLawKind::kElliptic;
  s.table_interp = interp;
  s.table_precision = prec;
  s.table_size = interp == Interp::kLinear ? 65536 : 1024;
  return s;
}

}  // namespace

TEST(RtLookups, CounterSeesAnAllocation) {
  EXPECT_EQ(allocations_in([] { ::operator delete(::operator new(16)); }), 1u);
}

TEST(RtLookups, AreNoexcept) {
  const ProfileSet* p = nullptr;
  ShedMonitor m;
  ProfileSlot* slot = nullptr;
  static_assert(noexcept(p->rocker().at(Phase{})));
  static_assert(noexcept(p->rocker().at(0.0)));
  static_assert(noexcept(p->crank_at(Phase{})));
  static_assert(noexcept(p->rocker_at(Phase{})));
  static_assert(noexcept(p->crank_law().crank_phase(Phase{})));
  static_assert(noexcept(p->cam().at(0.0)));
  static_assert(noexcept(p->pick().at(0.0)));
  static_assert(noexcept(Phase::from_rad(0.0)));
  static_assert(noexcept(Phase{} + Phase{}));
  static_assert(noexcept(m.update(ShedSpec{}, 0.0, PistonEnds{}, PistonEnds{})));
  static_assert(noexcept(slot->swap_at_row_boundary()));
  static_assert(noexcept(slot->active()));
  SUCCEED();
}

TEST(RtLookups, AllocateNothing) {
  for (Interp interp : {Interp::kLinear, Interp::kCubic, Interp::kQuintic}) {
    for (Precision prec : {Precision::kDouble, Precision::kFloat}) {
      if (interp == Interp::kLinear && prec == Precision::kFloat) continue;  // float32 linear misses 1e-7
      const ProfileSet p(spec(interp, prec));
      ShedMonitor shed;
      double sink = 0;
      const std::size_t n = allocations_in([&] {
        PhaseClock master({0, 0}, phase_step(15.5, 0.002));
        for (int i = 0; i < 20000; ++i) {
          master.tick();
          const Phase m = master.phase();
          sink += p.rocker().at(m).value + p.rocker().at(m.to_rad()).d1 + p.rocker_at(m).d2;
          const CrankSample c = p.crank_at(m);
          sink += c.phase + p.crank_law().crank_phase(m).to_rad();
          sink += p.cam().at(c.phase).position + p.pick().at(i * 1e-4).position;
          if (i % 500 == 0) shed.start(true, false, {false, true}, {true, false});
          sink +=
              static_cast<double>(shed.update(p.shed(), (i % 500) * 0.002, {false, false}, {false, false}));
        }
      });
      EXPECT_EQ(n, 0u) << interp_name(interp) << " " << precision_name(prec);
      EXPECT_TRUE(std::isfinite(sink));
    }
  }
}

TEST(RtLookups, RowBoundarySwapAllocatesNothing) {
  ProfileSlot slot(std::make_unique<const ProfileSet>(ProfileSpec{}));
  slot.publish(std::make_unique<const ProfileSet>(spec(Interp::kQuintic, Precision::kDouble)));
  bool swapped = false;
  EXPECT_EQ(allocations_in([&] { swapped = slot.swap_at_row_boundary(); }), 0u);
  EXPECT_TRUE(swapped);
  EXPECT_TRUE(slot.collect());
}
