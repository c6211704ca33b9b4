// libFuzzer target: a path tracer's saved sums (renderer/core, read back
// from an output folder by skyshell-bench --truth path to resume a run) on
// arbitrary bytes. The decoder may refuse, never crash, allocate from a
// damaged size or read out of bounds; a state it accepts has sums of its
// size and re-encodes to exactly the input. Seeds:
// tests/fuzz/corpus/path_trace_state/.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "sky/render/path_tracer.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The key the seeds were written for.
  const auto state = sky::render::PathTraceState::decode(std::span(data, size), "seed");
  if (!state) return 0;
  const std::size_t n = std::size_t(state->width) * state->height;
  if (state->sum.size() != n * 4 || state->sumSquares.size() != n * 3 || state->depthCount.size() != n) std::abort();
  const auto again = state->encode();
  if (again.size() != size || !std::equal(again.begin(), again.end(), data)) std::abort();
  return 0;
}
