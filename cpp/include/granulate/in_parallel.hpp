// The core's parallel regions, entered only when it runs on more than one thread.
#pragma once

#include <omp.h>

namespace granulate {

/// Runs region() on a team of OpenMP threads (an `omp parallel` region), or directly on the
/// calling thread when the core runs on one (omp_get_max_threads() == 1). The worksharing
/// constructs inside region() (omp for, single, critical) are orphaned: on one thread each runs
/// whole, in the order a team of one would, so the results are the same bits. libgomp builds a
/// team even for one thread and ends each of its barriers with a futex system call: 18 a step
/// for three small discs on one thread, 15-20 % of their run's CPU time.
template <class Region>
void in_parallel(Region&& region) {
  if (omp_get_max_threads() == 1) {
    region();
    return;
  }
#pragma omp parallel
  region();
}

}  // namespace granulate
