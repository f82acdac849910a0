// Options every command that runs the phone-bigram runtime shares: pose set, curve set,
// character, output rate, the steps to run, and the weights file to write.
#pragma once

#include <CLI/CLI.hpp>
#include <lipsyncd/lipsync.hpp>
#include <string>

#include "NumberOption.hpp"
#include "Output.hpp"

namespace lipsyncd::cli {

struct RuntimeOptions {
    std::string weights;        // where to write pose weights (CSV); empty: not asked for
    lipsync::RuntimeSpec spec;  // what lipsyncd's [mouth] table says too

    // `withWeights`: add --weights (commands whose main output is something else).
    void addTo(CLI::App& cmd, bool withWeights) {
        if (withWeights)
            cmd.add_option("--weights", weights,
                           "Write mouth-pose weights here (CSV, '-' for stdout)");
        cmd.add_option("--poses", spec.poses, "Pose set (config/poses/NAME.toml, or a file)")
            ->capture_default_str();
        cmd.add_option("--curves", spec.curves,
                       "Bigram curve set (config/curves/NAME.json, or a file)")
            ->capture_default_str();
        cmd.add_option("--runtime", spec.kind,
                       "bigram: the phone-bigram curves (paper 000); filter: the viseme-space "
                       "filter (paper 001, section 5), simpler and lower-latency")
            ->check(CLI::IsMember({"bigram", "filter"}))
            ->capture_default_str();
        cmd.add_option(
               "--phonemes", spec.phonemes,
               "Phoneme set of the schedule and curves: common, mandarin (common + ü), or a file")
            ->capture_default_str();
        cmd.add_option("--character", spec.character,
                       "Character file: a base curve set with some bigrams replaced");
        addNumberOption(cmd, "--weights-rate", spec.config.outputRate,
                        "Pose-weight frames per second", 1.0, 1000.0);
        cmd.add_flag("!--no-smoothing", spec.config.smoothing,
                     "Skip valley smoothing (for comparison)");
        cmd.add_flag("!--no-constraints", spec.config.constraints, "Skip pose-pair constraints");
        cmd.add_flag("!--no-speed-limits", spec.config.speedLimits, "Skip speed limits");
        cmd.add_flag("!--no-rest", spec.config.restInPauses,
                     "Do not force the mouth to rest in pauses and after speech");
        cmd.add_flag("!--no-loudness", spec.loudness,
                     "Do not let louder speech open the mouth wider (poses' loudness_gain)");
        cmd.add_flag("!--no-heard-jaw", spec.heardJaw,
                     "Take the jaw from the schedule's phonemes alone, not partly from the jaw "
                     "heights the front end's class scores point to (poses' heard_jaw)");
    }

    const PhonemeSet& phonemeSet() const { return PhonemeSet::named(spec.phonemes); }
    lipsync::Runtime load() const { return lipsync::Runtime(spec); }

    // The runtime over a schedule, loaded for this one call.
    PoseTrack animate(const PhonemeSchedule& schedule, const LevelTrack* levels = nullptr) const {
        return load().animate(schedule, levels);
    }

    void writeWeights(const PoseTrack& track) const {
        withOutputStream(weights, [&](std::ostream& out) { writePoseTrackCsv(out, track); });
    }
};

}  // namespace lipsyncd::cli
