// Options every command that runs the phone-bigram runtime shares: pose set, curve set,
// character, output rate, the steps to run, and the weights file to write.
#pragma once

#include <CLI/CLI.hpp>
#include <lipsyncd/lipsync.hpp>
#include <memory>
#include <string>

#include "Output.hpp"

namespace lipsyncd::cli {

struct RuntimeOptions {
    std::string weights;  // where to write pose weights (CSV); empty: not asked for
    std::string poses = "facefx";
    std::string curves = "english";
    std::string character;
    std::string runtime = "bigram";
    std::string phonemes = "common";
    lipsync::RuntimeConfig config;
    bool loudness = true;  // shape poses by the speech level where the audio is known

    // `withWeights`: add --weights (commands whose main output is something else).
    void addTo(CLI::App& cmd, bool withWeights) {
        if (withWeights)
            cmd.add_option("--weights", weights,
                           "Write mouth-pose weights here (CSV, '-' for stdout)");
        cmd.add_option("--poses", poses, "Pose set (config/poses/NAME.toml, or a file)")
            ->capture_default_str();
        cmd.add_option("--curves", curves, "Bigram curve set (config/curves/NAME.json, or a file)")
            ->capture_default_str();
        cmd.add_option("--runtime", runtime,
                       "bigram: the phone-bigram curves (paper 000); filter: the viseme-space "
                       "filter (paper 001, section 5), simpler and lower-latency")
            ->check(CLI::IsMember({"bigram", "filter"}))
            ->capture_default_str();
        cmd.add_option(
               "--phonemes", phonemes,
               "Phoneme set of the schedule and curves: common, mandarin (common + ü), or a file")
            ->capture_default_str();
        cmd.add_option("--character", character,
                       "Character file: a base curve set with some bigrams replaced");
        cmd.add_option("--weights-rate", config.outputRate, "Pose-weight frames per second")
            ->check(CLI::Range(1.0, 1000.0))
            ->capture_default_str();
        cmd.add_flag("!--no-smoothing", config.smoothing, "Skip valley smoothing (for comparison)");
        cmd.add_flag("!--no-constraints", config.constraints, "Skip pose-pair constraints");
        cmd.add_flag("!--no-speed-limits", config.speedLimits, "Skip speed limits");
        cmd.add_flag("!--no-rest", config.restInPauses,
                     "Do not force the mouth to rest in pauses and after speech");
        cmd.add_flag("!--no-loudness", loudness,
                     "Do not let louder speech open the mouth wider (poses' loudness_gain)");
    }

    struct Loaded {
        lipsync::PoseSet poses;
        lipsync::BigramCurveSet curves;
    };
    const PhonemeSet& phonemeSet() const { return PhonemeSet::named(phonemes); }

    Loaded load() const {
        auto poseSet = lipsync::PoseSet::named(poses);
        auto set = character.empty() ? lipsync::BigramCurveSet::named(curves, poseSet, phonemeSet())
                                     : lipsync::BigramCurveSet::load(findDataFile(character),
                                                                     poseSet, phonemeSet());
        return {std::move(poseSet), std::move(set)};
    }

    // The runtime over a schedule; with `levels` (the speech's frame levels) and loudness on,
    // louder speech opens wider within what each phoneme allows.
    PoseTrack animate(const PhonemeSchedule& schedule, const Loaded& loaded,
                      const LevelTrack* levels = nullptr) const {
        auto track =
            runtime == "filter"
                ? lipsync::animateFilter(schedule, loaded.curves, loaded.poses, config,
                                         phonemeSet())
                : lipsync::animate(schedule, loaded.curves, loaded.poses, config, phonemeSet());
        if (levels && loudness) lipsync::shapeByLoudness(loaded.poses, *levels, track);
        return track;
    }
    PoseTrack animate(const PhonemeSchedule& schedule, const LevelTrack* levels = nullptr) const {
        return animate(schedule, load(), levels);
    }

    void writeWeights(const PoseTrack& track) const {
        withOutputStream(weights, [&](std::ostream& out) { writePoseTrackCsv(out, track); });
    }
};

}  // namespace lipsyncd::cli
