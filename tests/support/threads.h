// Runs a computation on exactly n TBB worker threads, also on a machine with fewer cores, so that a
// test comparing thread counts compares what it says.
//
// TBB caps its workers at the core count: a tbb::global_control(max_allowed_parallelism, n) alone
// only lowers that cap (on one core, n = 2 still runs one thread), and a tbb::task_arena(n) alone
// gets no worker beyond the cap. Together they give n threads: the control raises the cap to n and
// the arena has n slots (measured under `taskset -c 0`: one thread with either alone, two with both).
#pragma once

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <utility>

namespace skybake::test {

template <class F>
decltype(auto) WithThreads(int n, F&& f) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(n));
  tbb::task_arena arena(n);
  return arena.execute(std::forward<F>(f));
}

}  // namespace skybake::test
