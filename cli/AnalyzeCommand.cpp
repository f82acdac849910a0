// lipsync analyze: audio to a phoneme schedule by the LPC front end.
#include <cmath>
#include <iomanip>
#include <iostream>
#include <lipsyncd/core.hpp>
#include <lipsyncd/dsp.hpp>

#include "Commands.hpp"
#include "FrontEndOptions.hpp"
#include "Output.hpp"
#include "RuntimeOptions.hpp"

namespace lipsyncd::cli {

namespace {
struct AnalyzeOptions {
    std::string input;
    std::string schedule;
    std::string format = "tsv";
    std::string frames;
    std::string features;
    FrontEndOptions frontEnd;
    RuntimeOptions runtime;
    bool quiet = false;
};

void writeFrames(std::ostream& out, const dsp::AnalysisResult& result, const PhonemeSet& set) {
    out << "time,energy_db,noise_floor_db,normalized_error,voiced,silent,class,confidence,"
           "runner_up,distance,runner_up_distance\n"
        << std::fixed;
    for (const auto& f : result.frames) {
        const auto& l = f.label;
        out << std::setprecision(3) << l.time << ',' << std::setprecision(1) << l.energyDb << ','
            << l.noiseFloorDb << ',' << std::setprecision(4) << f.features.normalizedError << ','
            << l.voiced << ',' << l.silent << ',' << set[l.phoneme].name << ','
            << std::setprecision(3) << l.confidence << ',' << set[l.runnerUp].name << ','
            << l.distance << ',' << l.runnerUpDistance << '\n';
    }
}

// One row a frame: the decided class, whether the gate called it silent, the heard jaw, then
// the feature vector the templates are matched on (spectrum in dB, then the extra features).
void writeFeatures(std::ostream& out, const dsp::AnalysisResult& result, const PhonemeSet& set) {
    out << "time,class,silent,jaw";
    const std::size_t n = result.frames.empty() ? 0 : result.frames[0].features.spectrum.size();
    for (std::size_t i = 0; i < n; ++i) out << ",f" << i;
    out << '\n' << std::fixed;
    for (const auto& f : result.frames) {
        const auto& l = f.label;
        out << std::setprecision(3) << l.time << ',' << set[l.phoneme].name << ',' << l.silent
            << ',' << std::setprecision(4) << l.jaw;
        for (float v : f.features.spectrum) out << ',' << v;
        out << '\n';
    }
}

void runAnalyze(const AnalyzeOptions& o) {
    const auto templates = o.frontEnd.loadTemplates();
    const auto& set = PhonemeSet::common();
    const auto result =
        dsp::analyzeFile(o.input, templates, set, o.frontEnd.config(), o.frontEnd.decode(),
                         o.frontEnd.raw(), !o.frames.empty() || !o.features.empty());
    printWarnings("analyze", result.warnings);
    if (result.nonFiniteSamples > 0)
        std::cerr << "lipsync analyze: warning: " << o.input << ": " << result.nonFiniteSamples
                  << " non-finite samples (NaN/inf) read as silence\n";
    if (!o.quiet)
        std::cerr << "lipsync analyze: " << o.input << ": " << std::fixed << std::setprecision(2)
                  << result.durationSeconds << " s at " << result.inputRate << " Hz, "
                  << result.schedule.size() << " segments (resampler delay " << std::setprecision(1)
                  << result.resamplerDelaySeconds * 1000 << " ms, " << o.frontEnd.decoderNote()
                  << ")\n";
    if (!o.schedule.empty())
        withOutputStream(o.schedule, [&](std::ostream& out) {
            if (o.format == "json")
                writeScheduleJson(out, result.schedule);
            else
                writeSchedule(out, result.schedule);
        });
    if (!o.frames.empty())
        withOutputStream(o.frames, [&](std::ostream& out) { writeFrames(out, result, set); });
    if (!o.features.empty())
        withOutputStream(o.features, [&](std::ostream& out) { writeFeatures(out, result, set); });
    if (!o.runtime.weights.empty())
        o.runtime.writeWeights(o.runtime.animate(result.schedule, &result.levels));
}
}  // namespace

void addAnalyzeCommand(CLI::App& app) {
    auto o = std::make_shared<AnalyzeOptions>();
    auto* cmd = app.add_subcommand(
        "analyze", "Analyse speech audio into a timed phoneme schedule (linear prediction)");
    cmd->add_option("input", o->input, "Audio file (WAV, FLAC, OGG; '-' for stdin)")->required();
    auto* schedule =
        cmd->add_option("--schedule,-s", o->schedule, "Write the schedule here ('-' for stdout)");
    cmd->add_option("--format", o->format, "Schedule format")
        ->check(CLI::IsMember({"tsv", "json"}))
        ->capture_default_str();
    cmd->add_option("--frames", o->frames,
                    "Also write per-frame energy, voicing, class, runner-up and distances (CSV)");
    cmd->add_option("--features", o->features,
                    "Also write each frame's feature vector (LPC spectrum in dB, then the extra "
                    "features), decided class and heard jaw (CSV, for training experiments)");
    cmd->add_flag("--quiet,-q", o->quiet, "No summary on stderr");
    o->frontEnd.addTo(*cmd);
    o->runtime.addTo(*cmd, true);
    cmd->callback([o, schedule] {
        if (o->schedule.empty() && o->runtime.weights.empty())
            throw CLI::ValidationError(schedule->get_name(),
                                       "nothing to write: give --schedule and/or --weights");
        runAnalyze(*o);
    });
}

}  // namespace lipsyncd::cli
