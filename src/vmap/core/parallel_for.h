#pragma once
// Independent jobs 0..count-1 spread over a few threads, the calling one included: for work whose result does
// not depend on which thread did which job (key images described, links analysed).

#include <cstddef>
#include <functional>

namespace vmap {

// Calls job(i) once for every i in [0, count), on at most `threads` threads (at least one: the caller's), and
// returns when all are done. After a job throws, no new job starts, and the first exception is rethrown here.
void ParallelFor(size_t count, int threads, const std::function<void(size_t)>& job);

}  // namespace vmap
