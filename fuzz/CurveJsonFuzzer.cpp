// Fuzz target: bytes as a curve set or character file (JSON) for the shipped poses. A set
// that loads animates a short schedule to finite weights; a bad file is an InputError.
#include <cmath>
#include <cstdint>
#include <lipsyncd/lipsync.hpp>

#include "MemoryFile.hpp"

using namespace lipsyncd;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const auto poses = lipsync::PoseSet::named("facefx");
    const auto file = fuzz::memoryFileOf(data, size);
    if (!file) return 0;
    try {
        const auto curves = lipsync::BigramCurveSet::load(file->path(), poses);
        const PhonemeSchedule schedule = {
            {0.0, 0.1, "sil", 1}, {0.1, 0.25, "aa", 1}, {0.25, 0.3, "bmp", 1}};
        for (const float v : lipsync::animate(schedule, curves, poses, {}).values)
            if (!std::isfinite(v)) __builtin_trap();
    } catch (const InputError&) {
    }
    return 0;
}
