// lipsync animate: a phoneme schedule to mouth-pose weights (the phone-bigram runtime), and
// lipsync curves generate: the curve set from its rules.
#include <iostream>
#include <lipsyncd/dsp.hpp>
#include <optional>

#include "Commands.hpp"
#include "Corpus.hpp"
#include "Output.hpp"
#include "RuntimeOptions.hpp"

namespace lipsyncd::cli {

namespace {
struct AnimateOptions {
    std::string schedule;
    std::string labels = "auto";
    double delay = -1;  // < 0: offline
    std::string audio;  // the speech the schedule belongs to: its loudness shapes the mouth
    RuntimeOptions runtime;
};

void runAnimate(const AnimateOptions& o) {
    const auto schedule = readLabels(o.schedule, o.labels, &o.runtime.phonemeSet());
    if (o.delay >= 0 && o.runtime.spec.kind != "bigram")
        throw CLI::ValidationError("--delay", "streaming is for --runtime bigram");
    if (o.delay < 0) {
        std::optional<LevelTrack> levels;
        if (!o.audio.empty()) {
            const auto audio = dsp::readAudioFile(o.audio);
            printWarnings("animate", audio.warnings);
            levels = dsp::measureLevels(audio.samples, audio.sampleRate);
        }
        o.runtime.writeWeights(o.runtime.animate(schedule, levels ? &*levels : nullptr));
        return;
    }
    if (!o.audio.empty())
        throw CLI::ValidationError("--audio", "loudness shaping is for offline runs (no --delay)");
    // Streaming, as the daemon runs it: segment by segment, with the given delay.
    const auto runtime = o.runtime.load();
    auto stream = runtime.streaming(o.delay);
    PoseTrack track;
    for (const auto& s : schedule) stream.push(s, track);
    stream.finish(track);
    o.runtime.writeWeights(track);
}

struct GenerateOptions {
    std::string rules = "curves/english-rules.toml";
    std::string output;
    std::string poses = "facefx";
    std::string phonemes = "common";
    std::string additionsFor, base;
};
}  // namespace

void addAnimateCommand(CLI::App& app) {
    auto o = std::make_shared<AnimateOptions>();
    auto* cmd = app.add_subcommand(
        "animate", "Turn a phoneme schedule into mouth-pose weights (phone-bigram runtime)");
    cmd->add_option("--schedule", o->schedule, "Schedule or labels (TSV/.lab; '-' for stdin)")
        ->required();
    cmd->add_option("--weights", o->runtime.weights, "Pose weights to write (CSV; '-' for stdout)")
        ->required();
    cmd->add_option("--labels", o->labels,
                    "Schedule alphabet: auto, common, arpabet, ipa, espeak-en, or a map file")
        ->capture_default_str();
    cmd->add_option("--delay", o->delay,
                    "Run streaming with this delay in seconds (0: causal), as the daemon does");
    cmd->add_option("--audio", o->audio,
                    "The speech the schedule belongs to (WAV...): louder speech opens the mouth "
                    "wider, as in analyze and say");
    o->runtime.addTo(*cmd, false);
    cmd->callback([o] { runAnimate(*o); });
}

void addCurvesCommand(CLI::App& app) {
    auto* curves = app.add_subcommand("curves", "Bigram curve sets: generate one from its rules");
    curves->require_subcommand(1);
    auto o = std::make_shared<GenerateOptions>();
    auto* gen = curves->add_subcommand(
        "generate", "Build a curve set from per-class targets and coarticulation rules");
    gen->add_option("--rules", o->rules, "Rules file (TOML)")->capture_default_str();
    gen->add_option("-o,--output", o->output, "Curve set to write (JSON)")->required();
    gen->add_option("--poses", o->poses, "Pose set")->capture_default_str();
    gen->add_option("--phonemes", o->phonemes, "Phoneme set (common, mandarin, or a file)")
        ->capture_default_str();
    gen->add_option("--additions-for", o->additionsFor,
                    "Write only the bigrams with this class, as a character file on --base "
                    "(a language's additions)");
    gen->add_option("--base", o->base, "The curve set the additions extend");
    gen->callback([o] {
        const auto poses = lipsync::PoseSet::named(o->poses);
        const auto& phonemes = PhonemeSet::named(o->phonemes);
        const auto set = lipsync::generateCurveSet(findDataFile(o->rules), poses, phonemes);
        if (!o->additionsFor.empty()) {
            const auto cls = phonemes.find(o->additionsFor);
            if (!cls)
                throw CLI::ValidationError(
                    "--additions-for",
                    "'" + o->additionsFor + "' is not a class of " + o->phonemes);
            if (o->base.empty())
                throw CLI::ValidationError("--base", "needed with --additions-for");
            set.saveAdditions(o->output, o->base, *cls, poses, phonemes);
        } else {
            set.save(o->output, poses, phonemes);
        }
        std::cerr << "lipsync curves: wrote " << o->output << '\n';
    });
}

}  // namespace lipsyncd::cli
