// Options every command that runs the front end shares: templates, channel, raw input.
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <lipsyncd/dsp.hpp>
#include <optional>
#include <string>
#include <vector>

#include "NameValue.hpp"
#include "NumberOption.hpp"

namespace lipsyncd::cli {

struct FrontEndOptions {
    std::string templates;  // empty: the shipped default
    int channel = -1;
    std::string rawSpec;
    std::string resampler = "medium";
    dsp::SegmenterConfig segmenter;
    dsp::DecoderConfig decoder;
    std::string transitions;  // empty: the shipped default
    dsp::ClassifierConfig classifier;
    std::vector<std::string> classBias;  // CLASS=DB, over the set's class_bias_db
    bool noClassBias = false;

    void addTo(CLI::App& cmd) {
        cmd.add_option("--templates", templates,
                       "Template set (JSON; default: config/templates/default.json)");
        cmd.add_option("--channel", channel,
                       "Analyse only this channel (0-based) instead of the mono mix")
            ->check(CLI::Range(0, 63));
        cmd.add_option("--raw", rawSpec,
                       "Input is headerless PCM: RATE:FORMAT:CHANNELS, e.g. 16000:s16:1 "
                       "(formats s8 u8 s16 s24 s32 f32 f64, little-endian)");
        cmd.add_option("--resampler", resampler,
                       "Resampler to the 10 kHz analysis rate. medium (the passband the "
                       "templates were trained through) or low (shorter): a polyphase FIR "
                       "holding back a few ms (libsoxr for odd rates and whole files above "
                       "16 kHz); high, veryhigh: libsoxr's steeper filters")
            ->check(CLI::IsMember({"low", "medium", "high", "veryhigh"}))
            ->capture_default_str();
        // Shorter runs are flicker and merge into their neighbour; longer holds mean fewer,
        // steadier segments and a longer streaming delay (the longest minimum plus a hop).
        addNumberOption(cmd, "--min-vowel", segmenter.minVowelSeconds,
                        "Shortest vowel segment, seconds", 0.0, 0.5);
        addNumberOption(cmd, "--min-consonant", segmenter.minConsonantSeconds,
                        "Shortest consonant segment, seconds", 0.0, 0.5);
        addNumberOption(cmd, "--min-silence", segmenter.minSilenceSeconds,
                        "Shortest silence, seconds", 0.0, 0.5);
        addNumberOption(cmd, "--stop-closure", segmenter.stopClosureSeconds,
                        "A silence shorter than this, seconds, between two speech segments is "
                        "a stop's closure and takes the stop's class (0: off)",
                        0.0, 0.5);
        addNumberOption(
            cmd, "--silence-below-peak", classifier.silenceBelowPeakDb,
            "Frames this many dB below the recent speech peak are silence, whatever the noise "
            "floor (0: off)",
            0.0, 80.0);
        addNumberOption(
            cmd, "--jaw-spread", classifier.jawSpreadDb,
            "How far (dB of spectral distance) a class may lie from the nearest and still "
            "count towards the jaw height heard in a frame",
            0.01, 20.0);
        addNumberOption(
            cmd, "--class-network-db", classifier.classNetworkDb,
            "With a template set that has a class network: dB of distance added per nat a "
            "class's likelihood lies below the likeliest class's (0: the templates alone)",
            0.0, 20.0);
        addNumberOption(
            cmd, "--class-prior-scale", classifier.classPriorScale,
            "With a class network: how much of each class's share of the training frames its "
            "posterior is divided by (1: all, the hybrid's scaled likelihood; 0: none, common "
            "classes favoured)",
            0.0, 1.0);
        cmd.add_option("--class-bias", classBias,
                       "dB added to a class's distance, CLASS=DB (repeatable; over the template "
                       "set's class_bias_db, a negative value favours the class)");
        cmd.add_flag("--no-class-bias", noClassBias,
                     "Leave out the template set's class bias (class_bias_db)");
        addDecoderTo(cmd);
    }

    void addDecoderTo(CLI::App& cmd) {
        // Viterbi over classes (dsp::ViterbiDecoder): the lag is how long a frame waits for
        // the frames after it before its class is decided.
        cmd.add_flag("!--no-decoder", decoder.enabled,
                     "Classify frame by frame (no Viterbi decoding over classes)");
        addNumberOption(cmd, "--lag", decoder.lagSeconds,
                        "Decoder lag, seconds: how long a frame waits for later frames", 0.0, 2.0);
        cmd.add_flag_callback(
            "--offline", [this] { decoder.lagSeconds = -1; },
            "Decode offline: every frame decided from the whole input (files only)");
        addNumberOption(cmd, "--group-share", decoder.groupShare,
                        "How much a class pays for the share of the frame its visual group "
                        "lacks against the likeliest group's (the group decided by all its "
                        "classes together before the class; 0: the nearest class alone)",
                        0.0, 100.0);
        addNumberOption(cmd, "--group-spread", decoder.groupSpreadDb,
                        "dB of distance over which a class's weight in its group's share falls "
                        "by a factor e",
                        0.05, 20.0);
        cmd.add_option("--transitions", transitions,
                       "Class transition model (JSON; default: "
                       "config/decoder/english-transitions.json)");
    }

    dsp::TemplateSet loadTemplates() const {
        auto set = dsp::TemplateSet::named(templates);
        if (noClassBias) set.classBiasDb.clear();
        for (const auto& item : classBias) {
            const auto pair = parseNameValue(item);
            if (!pair)
                throw InputError("--class-bias: '" + item + "' is not CLASS=DB (e.g. bmp=0.3)");
            set.classBiasDb[pair->first] = static_cast<float>(pair->second);
        }
        if (!classBias.empty()) set.validate("--class-bias");
        return set;
    }
    dsp::DecodeOptions decode() const { return {channel}; }
    // How classes were decided, for a report: the streaming lag is part of what was measured.
    std::string decoderNote() const {
        if (!decoder.enabled) return "frame by frame";
        if (decoder.lagSeconds < 0) return "decoded offline";
        return "decoder lag " + std::to_string(std::lround(decoder.lagSeconds * 1000)) + " ms";
    }
    std::optional<dsp::RawFormat> raw() const {
        if (rawSpec.empty()) return std::nullopt;
        return dsp::RawFormat::parse(rawSpec);
    }
    dsp::FrontEndConfig config() const {
        dsp::FrontEndConfig c;
        c.segmenter = segmenter;
        c.decoder = decoder;
        c.classifier = classifier;
        if (decoder.enabled && !transitions.empty())
            c.transitions = dsp::TransitionModel::load(findDataFile(transitions));
        if (resampler == "low") c.resamplerQuality = dsp::ResamplerQuality::Low;
        if (resampler == "high") c.resamplerQuality = dsp::ResamplerQuality::High;
        if (resampler == "veryhigh") c.resamplerQuality = dsp::ResamplerQuality::VeryHigh;
        return c;
    }
};

}  // namespace lipsyncd::cli
