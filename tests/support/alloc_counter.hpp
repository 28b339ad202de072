// Counts global operator new calls on the calling thread while enabled. The replacement operators
// live in alloc_counter.cpp, a translation unit of their own, so the compiler never pairs an inlined
// replacement with the standard library's deallocation in the same function.
#pragma once

#include <cstddef>

namespace loom::test {

void count_allocations(bool on) noexcept;
std::size_t allocations() noexcept;
void reset_allocations() noexcept;

}  // namespace loom::test
