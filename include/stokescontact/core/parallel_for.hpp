#pragma once
// parallel_for: the loops of the contact step over pairs and bodies (each index writes only
// its own output slot) shared out over OpenMP threads, with the same results as the serial
// loop, bit for bit: no reduction is reordered, every index runs the same code. An exception
// thrown by the body (a validation error naming a pair) leaves the loop and is rethrown on
// the calling thread after it, the first one by index; without OpenMP, or below
// kParallelForMinCount indices (or the caller's min_count), the loop runs serially.
#include <cstddef>
#include <exception>
#include <vector>

namespace stokescontact {

// Below this many indices the threads' start-up costs more than the loop (a few microseconds
// per parallel region against about 0.1-1 us per pair distance).
inline constexpr std::ptrdiff_t kParallelForMinCount = 2048;

// `min_count`: the fewest indices worth the threads; a loop of a few large items (chunks of
// a longer loop) passes a smaller one.
template <class Body>
void parallel_for(std::ptrdiff_t count, Body&& body, std::ptrdiff_t min_count = kParallelForMinCount) {
#ifdef _OPENMP
  if (count >= min_count && count > 1) {
    std::exception_ptr first;
    std::ptrdiff_t first_index = count;
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t k = 0; k < count; ++k) {
      try {
        body(k);
      } catch (...) {
#pragma omp critical(stokescontact_parallel_for)
        if (k < first_index) {
          first_index = k;
          first = std::current_exception();
        }
      }
    }
    if (first) std::rethrow_exception(first);
    return;
  }
#endif
  for (std::ptrdiff_t k = 0; k < count; ++k) body(k);
}

}  // namespace stokescontact
