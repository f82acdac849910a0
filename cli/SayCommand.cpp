// lipsync say: espeak-ng speaks a line; its own phoneme events give the exact schedule.
#include <iostream>
#include <lipsyncd/core.hpp>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/tts.hpp>

#include "Commands.hpp"
#include "Output.hpp"
#include "RuntimeOptions.hpp"

namespace lipsyncd::cli {

namespace {
struct SayOptions {
    std::string text;
    std::string voice = "en-us";
    int rate = 0;
    int pitch = -1;
    std::string wav;
    std::string schedule;
    bool raw = false;
    RuntimeOptions runtime;
};

void runSay(const SayOptions& o) {
    EspeakSynthesizer synth;
    const auto speech = synth.synthesize({o.text, o.voice, o.rate, o.pitch});
    if (!o.wav.empty()) dsp::writeWavFile(o.wav, speech.samples, speech.sampleRate);
    if (o.schedule.empty() && o.runtime.weights.empty()) return;
    PhonemeSchedule schedule = speech.phonemes;
    if (!o.raw) {
        std::vector<std::string> warnings;
        schedule = mapSchedule(speech.phonemes, espeakMapForVoice(o.voice), &warnings);
        printWarnings("say", warnings);
    }
    if (!o.schedule.empty())
        withOutputStream(o.schedule,
                         [&](std::ostream& out) { writeSchedule(out, schedule, false); });
    if (!o.runtime.weights.empty()) {
        if (o.raw)
            throw CLI::ValidationError("--weights", "needs the common set: drop --raw-phonemes");
        // The exact schedule, opened as wide as the synthesised speech is loud.
        const auto levels = dsp::measureLevels(speech.samples, speech.sampleRate);
        o.runtime.writeWeights(o.runtime.animate(schedule, &levels));
    }
}
}  // namespace

void addSayCommand(CLI::App& app) {
    auto o = std::make_shared<SayOptions>();
    auto* cmd = app.add_subcommand(
        "say", "Speak TEXT with espeak-ng; write the speech and its exact phoneme schedule");
    cmd->add_option("text", o->text, "What to say")->required();
    cmd->add_option("--voice", o->voice,
                    "espeak-ng voice, variants with '+' (en-us+f2); its language needs a "
                    "phoneme map, config/phonemes/espeak-LANG.toml: 50 languages (en, fr, es, "
                    "ru, bg, ro, cs, nl, ca, be, el, da by hand; de, it, pt, pl, sv, nb, fi, hu, "
                    "tr, uk, sk, hr, hi, ko, id, vi, ... from espeak-ng's IPA)")
        ->capture_default_str();
    cmd->add_option("--rate", o->rate, "Words per minute (default: the voice's)")
        ->check(CLI::Range(80, 450));
    cmd->add_option("--pitch", o->pitch, "Pitch 0-100 (default: the voice's)")
        ->check(CLI::Range(0, 100));
    cmd->add_option("--wav", o->wav, "Write the speech to this WAV file");
    cmd->add_option("--schedule", o->schedule, "Write the phoneme schedule (TSV, '-' for stdout)");
    cmd->add_flag("--raw-phonemes", o->raw,
                  "Schedule in espeak-ng's own mnemonics instead of the common set");
    o->runtime.addTo(*cmd, true);
    cmd->callback([o] {
        if (o->wav.empty() && o->schedule.empty() && o->runtime.weights.empty())
            throw CLI::ValidationError("say",
                                       "nothing to write: give --wav, --schedule and/or --weights");
        runSay(*o);
    });
}

}  // namespace lipsyncd::cli
