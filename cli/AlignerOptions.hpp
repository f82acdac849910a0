// Options every command that runs the known-script aligner shares (align, eval --align): its
// floors and costs, the second pass, and the common reductions.
#pragma once

#include <CLI/CLI.hpp>
#include <cctype>
#include <lipsyncd/dsp.hpp>
#include <string>
#include <vector>

#include "NumberOption.hpp"

namespace lipsyncd::cli {

struct AlignerOptions {
    dsp::AlignerConfig config;
    bool reductions = true;
    std::vector<CLI::Option*> added;  // what addTo() added: a command may exclude them together

    // `when`: what the options depend on, said before each help text ("With --align"), or empty.
    void addTo(CLI::App& cmd, const std::string& when = "") {
        const auto help = [&](std::string text) {
            if (when.empty()) {
                text[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(text[0])));
                return text;
            }
            return when + ": " + text;
        };
        // A cost, share or floor: a number from 0 to `max`, its default shown.
        const auto number = [&](const std::string& name, float& field, const std::string& text,
                                double max) {
            added.push_back(addNumberOption(cmd, name, field, help(text), 0.0, max));
        };
        number("--min-word-confidence", config.minWordConfidence,
               "words placed with less confidence get audio-only analysis; in a line whose median "
               "word confidence reaches it, a word needs only 0.4 of that median, and the word of "
               "a one-word line 0.1 (never more than this)",
               1.0);
        number("--reduction-cost", config.reductionCost,
               "cost of saying a word another way than espeak-ng reads it", 100.0);
        number("--silence-in-speech-cost", config.silenceInSpeechCost,
               "cost per frame of silence where the energy gate hears speech", 100.0);
        number("--second-pass-prior", config.fileAdaptationPriorFrames,
               "align a second time on templates moved toward the file's own voice (what the "
               "first pass placed); the templates weigh as this many frames (0: one pass)",
               1000.0);
        number("--class-network-share", config.classNetworkShare,
               "how much of the class network's term (and the class bias) the aligner weighs "
               "beside the templates' distances (0: the templates alone)",
               1.0);
        added.push_back(cmd.add_flag(
            "!--no-reductions", reductions,
            help("follow espeak-ng's reading only, without the common reductions "
                 "(config/reductions/LANG.toml: weak forms, t/d and schwa deletion)")));
    }
};

}  // namespace lipsyncd::cli
