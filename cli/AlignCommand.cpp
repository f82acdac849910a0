// lipsync align: audio plus the words spoken in it → the schedule, by forced alignment of
// espeak-ng's reading of the words on the front end's per-frame distances.
#include <iomanip>
#include <iostream>
#include <lipsyncd/core.hpp>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/tts.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "AlignerOptions.hpp"
#include "Commands.hpp"
#include "Corpus.hpp"
#include "FrontEndOptions.hpp"
#include "Output.hpp"
#include "RuntimeOptions.hpp"

namespace lipsyncd::cli {

namespace {
struct AlignOptions {
    std::string input;
    std::string text;
    std::string textFile;
    std::string voice = "en-us";
    std::string schedule;
    std::string words;
    std::string format = "tsv";
    AlignerOptions aligner;
    FrontEndOptions frontEnd;
    RuntimeOptions runtime;
    std::string speaker;  // a speaker file (lipsyncd's speaker_file): read, then written back
    bool quiet = false;
};

void writeWords(std::ostream& out, const std::vector<dsp::AlignedWord>& words) {
    out << "# start\tend\tword\tconfidence\tplaced\texcess_db\tduration_ratio\n"
        << std::fixed << std::setprecision(3);
    for (const auto& w : words)
        out << w.start << '\t' << w.end << '\t' << w.text << '\t' << w.confidence << '\t'
            << (w.placed ? "yes" : "no") << '\t' << w.excessDb << '\t' << w.durationRatio << '\n';
}

void writeJson(std::ostream& out, const dsp::AlignFileResult& r) {
    nlohmann::json doc;
    std::ostringstream schedule;
    writeScheduleJson(schedule, r.schedule);
    doc["schedule"] = nlohmann::json::parse(schedule.str());
    doc["words"] = nlohmann::json::array();
    for (const auto& w : r.alignment.words)
        doc["words"].push_back({{"word", w.text},
                                {"start", w.start},
                                {"end", w.end},
                                {"confidence", w.confidence},
                                {"placed", w.placed}});
    doc["unexplained"] = nlohmann::json::array();  // stretches no word explains (audio-only)
    for (const auto& [a, b] : r.alignment.unexplained) doc["unexplained"].push_back({a, b});
    doc["fell_back"] = r.fellBack;
    doc["warnings"] = r.warnings;
    out << doc.dump(1) << '\n';
}

void runAlign(const AlignOptions& o) {
    const std::string text = o.textFile.empty() ? o.text : readTextFile(o.textFile);
    const auto templates = o.frontEnd.loadTemplates();
    // The speaker's voice from the lines before (a file that does not exist yet: none), and
    // this line added to it.
    std::optional<dsp::SpeakerAdaptation> speaker;
    if (!o.speaker.empty()) {
        speaker.emplace(dsp::carriedVoice(templates, o.aligner.config));
        if (std::filesystem::exists(o.speaker)) speaker->load(o.speaker);
    }
    EspeakSynthesizer synth;
    const auto r = alignText(synth, o.input, text, o.voice, templates, o.frontEnd.config(),
                             o.aligner.config, o.frontEnd.decode(), o.frontEnd.raw(),
                             o.aligner.reductions, speaker ? &*speaker : nullptr);
    if (speaker) speaker->save(o.speaker);
    printWarnings("align", r.warnings);
    if (!o.quiet) {
        const auto placed = std::count_if(r.alignment.words.begin(), r.alignment.words.end(),
                                          [](const dsp::AlignedWord& w) { return w.placed; });
        std::cerr << "lipsync align: " << o.input << ": " << std::fixed << std::setprecision(2)
                  << r.durationSeconds << " s, " << placed << " of " << r.alignment.words.size()
                  << " words placed (speaking rate x" << r.timeScale << " of espeak-ng's)"
                  << (r.fellBack ? ", FELL BACK to audio-only analysis" : "") << '\n';
    }
    if (!o.schedule.empty())
        withOutputStream(o.schedule, [&](std::ostream& out) {
            if (o.format == "json")
                writeJson(out, r);
            else
                writeSchedule(out, r.schedule);
        });
    if (!o.words.empty())
        withOutputStream(o.words, [&](std::ostream& out) { writeWords(out, r.alignment.words); });
    if (!o.runtime.weights.empty())
        o.runtime.writeWeights(o.runtime.animate(r.schedule, &r.levels));
}
}  // namespace

void addAlignCommand(CLI::App& app) {
    auto o = std::make_shared<AlignOptions>();
    auto* cmd = app.add_subcommand(
        "align", "Align the known words of a recording on its audio (forced alignment)");
    cmd->add_option("input", o->input, "Audio file (WAV, FLAC, OGG; '-' for stdin)")->required();
    auto* text = cmd->add_option("--text", o->text, "The words spoken in the audio");
    auto* file = cmd->add_option("--text-file", o->textFile, "A file holding the words");
    text->excludes(file);
    auto* schedule =
        cmd->add_option("--schedule,-s", o->schedule, "Write the schedule here ('-' for stdout)");
    cmd->add_option("--format", o->format,
                    "Schedule format (json: an object with the schedule, the words and warnings)")
        ->check(CLI::IsMember({"tsv", "json"}))
        ->capture_default_str();
    cmd->add_option("--words", o->words,
                    "Write each word's start, end, confidence and whether it was placed (TSV)");
    cmd->add_option("--voice", o->voice,
                    "espeak-ng voice whose reading of the words to follow (its language)")
        ->capture_default_str();
    o->aligner.addTo(*cmd);
    cmd->add_option("--speaker", o->speaker,
                    "A speaker file: align on the voice the earlier lines taught it, and add this "
                    "line's (created when missing; lipsyncd's speaker_file has the same format)");
    addNumberOption(*cmd, "--speaker-network-epochs", o->aligner.config.speakerNetworkEpochs,
                    "With --speaker: the line also trains the speaker's class and jaw networks "
                    "further on its placed frames, this many passes (0: they stay as they are)",
                    0, 100);
    cmd->add_flag("--quiet,-q", o->quiet, "No summary on stderr");
    o->frontEnd.addTo(*cmd);
    o->runtime.addTo(*cmd, true);
    cmd->callback([o, schedule, text, file] {
        if (text->count() == 0 && file->count() == 0)
            throw CLI::ValidationError("--text",
                                       "give the words: --text WORDS or --text-file FILE");
        if (o->schedule.empty() && o->words.empty() && o->runtime.weights.empty())
            throw CLI::ValidationError(
                schedule->get_name(),
                "nothing to write: give --schedule, --words and/or --weights");
        runAlign(*o);
    });
}

}  // namespace lipsyncd::cli
