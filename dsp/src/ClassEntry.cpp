#include "ClassEntry.hpp"

#include <cstring>

#include "VectorLanes.hpp"

namespace lipsyncd::dsp {

namespace {
using Lanes = FloatLanes;
using Indices = IntLanes;
}  // namespace

LIPSYNCD_VECTOR_CLONES void bestEntries(const float* exitScore, const float* transition,
                                        std::size_t classes, std::size_t stride, float unreachable,
                                        float* enter, int* entryFrom) {
    for (std::size_t to = 0; to < stride; to += 8) {
        Lanes best = unreachable - Lanes{};
        Indices from = Indices{} - 1;
        for (std::size_t j = 0; j < classes; ++j) {
            Lanes cost;
            std::memcpy(&cost, transition + j * stride + to, sizeof cost);
            const Lanes v = exitScore[j] + cost;
            // Strictly better, or the first to reach the starting value: a later equal value
            // never takes the place of an earlier one.
            const Indices better = v < best;
            const Indices first = (v == best) & (from == -1);
            from = (better | first) ? static_cast<int>(j) + Indices{} : from;
            best = better ? v : best;
        }
        std::memcpy(enter + to, &best, sizeof best);
        std::memcpy(entryFrom + to, &from, sizeof from);
    }
}

}  // namespace lipsyncd::dsp
