// Fuzz target: bytes as a phoneme schedule (TSV / .lab), then through the bigram runtime.
// A schedule read is bounded (finite times within a day, ordered); its pose weights finite.
#include <cmath>
#include <cstdint>
#include <lipsyncd/core.hpp>
#include <lipsyncd/lipsync.hpp>
#include <sstream>

using namespace lipsyncd;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const auto poses = lipsync::PoseSet::named("facefx");
    static const auto curves = lipsync::BigramCurveSet::named("english", poses);
    std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
    try {
        const auto schedule = readSchedule(in, "fuzz.tsv");
        for (const auto& s : schedule)
            if (!(s.start >= 0 && s.end > s.start && s.end <= 86400)) __builtin_trap();
        if (schedule.empty() || schedule.back().end > 30) return 0;  // keep each run short
        const auto track = lipsync::animate(schedule, curves, poses, {});
        for (const float v : track.values)
            if (!std::isfinite(v)) __builtin_trap();
    } catch (const InputError&) {
    }
    return 0;
}
