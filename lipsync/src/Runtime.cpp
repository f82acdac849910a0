// The runtime built from names, for the `lipsync` tool and lipsyncd alike: one loader, so a
// key the tool has (--phonemes) can never go missing in the service again.
#include <lipsyncd/lipsync.hpp>

namespace lipsyncd::lipsync {

namespace {
// Runs one loader; its error says which of the spec's names it was loading (`what`).
template <class Load>
auto loadField(const std::string& what, Load load) {
    try {
        return load();
    } catch (const InputError& e) {
        throw InputError(what + ": " + e.what());
    }
}
}  // namespace

Runtime::Runtime(RuntimeSpec spec)
    : spec_(std::move(spec)),
      phonemes_(loadField("phonemes '" + spec_.phonemes + "'",
                          [&] { return &PhonemeSet::named(spec_.phonemes); })),
      poses_(loadField("poses '" + spec_.poses + "'", [&] { return PoseSet::named(spec_.poses); })),
      // A curve set speaks one phoneme set: its error names the set it was read against.
      curves_(
          spec_.character.empty()
              ? loadField("curves '" + spec_.curves + "' (phonemes '" + spec_.phonemes + "')",
                          [&] { return BigramCurveSet::named(spec_.curves, poses_, *phonemes_); })
              : loadField("character '" + spec_.character + "' (phonemes '" + spec_.phonemes + "')",
                          [&] {
                              return BigramCurveSet::load(findDataFile(spec_.character), poses_,
                                                          *phonemes_);
                          })) {
    if (spec_.kind != "bigram" && spec_.kind != "filter")
        throw InputError("runtime '" + spec_.kind + "': must be \"bigram\" or \"filter\"");
}

PoseTrack Runtime::animate(std::span<const PhonemeSegment> schedule,
                           const LevelTrack* levels) const {
    auto track = spec_.kind == "filter"
                     ? animateFilter(schedule, curves_, poses_, spec_.config, *phonemes_)
                     : lipsync::animate(schedule, curves_, poses_, spec_.config, *phonemes_);
    if (levels && spec_.heardJaw) blendHeardJaw(poses_, *levels, track);
    if (levels && spec_.loudness) shapeByLoudness(poses_, *levels, schedule, *phonemes_, track);
    // The heard jaw's 40 ms smoothing fills the dips between syllables: deepened where it set
    // most of the jaw, speech analysed from audio alone (known phonemes dip in their curves).
    if (levels && spec_.heardJaw && !levels->jaw.empty() && !levels->aligned)
        deepenDips(poses_, track);
    return track;
}

StreamingRuntime Runtime::streaming(double delaySeconds) const {
    return StreamingRuntime(curves_, poses_, delaySeconds, spec_.config, *phonemes_);
}

}  // namespace lipsyncd::lipsync
