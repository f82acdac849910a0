// The inner step of the class Viterbi (ViterbiDecoder::step): for every class, the cheapest way
// in from the last state of another class. All destination classes at once, eight to a vector,
// so the cost is a pass over the transition matrix instead of one dependent chain of minima
// per class.
#pragma once

#include <cstddef>

namespace lipsyncd::dsp {

// exitScore[from] (from < classes; entries up to `stride` readable), transition[from * stride +
// to]: the cost of entering `to` from `from`, `stride` a multiple of 8 with padding entries at
// least `unreachable`. For every `to` < stride: enter[to] = min(unreachable, min over from of
// exitScore[from] + transition), and entryFrom[to] = the first `from` (lowest index) that gives
// exactly that value, −1 when none does.
void bestEntries(const float* exitScore, const float* transition, std::size_t classes,
                 std::size_t stride, float unreachable, float* enter, int* entryFrom);

}  // namespace lipsyncd::dsp
