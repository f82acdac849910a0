// lipsync calibrate: a speaker's own templates, on top of a base set for the classes not heard,
// from a few sustained sounds (aa.wav, ih.wav, bmp.wav, ...) or from read speech with its words
// (NAME.wav + NAME.txt: the known-script aligner labels the frames).
#include <algorithm>
#include <iostream>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/tts.hpp>
#include <optional>

#include "Commands.hpp"
#include "Corpus.hpp"

namespace lipsyncd::cli {

namespace {
struct CalibrateOptions {
    std::string folder;
    std::string output;
    std::string base;
    std::string voice = "en-us";
    int clusters = 2;
};

// "aa.wav", "aa-2.wav", "aa_take3.wav" all belong to class "aa".
std::string classOfFile(const std::filesystem::path& file) {
    const auto stem = file.stem().string();
    return stem.substr(0, stem.find_first_of("-_."));
}

// The classes recorded, each once, in the order first heard.
void addOnce(std::vector<std::string>& classes, const std::string& cls) {
    if (std::find(classes.begin(), classes.end(), cls) == classes.end()) classes.push_back(cls);
}

bool isAudio(const std::filesystem::path& file) {
    const auto ext = file.extension().string();
    return ext == ".wav" || ext == ".flac" || ext == ".ogg";
}

// Read speech: every recording with its words beside it (NAME.txt) is aligned on them, and its
// frames train the classes the alignment places, as `lipsync train` does with reference labels.
// A file with a word the aligner could not place is left out: its schedule there would be the
// front end's own guess, and calibrating on that teaches the templates their own mistakes.
void addReadSpeech(const CalibrateOptions& o, const dsp::TemplateSet& base,
                   dsp::TemplateTrainer& trainer, const dsp::AnalysisConfig& analysis,
                   std::vector<std::string>& recorded) {
    std::optional<EspeakSynthesizer> synth;  // started only when there are words to read
    for (const auto& entry : std::filesystem::directory_iterator(o.folder)) {
        if (!isAudio(entry.path())) continue;
        const auto words = wordsBeside(entry.path());
        if (!words) continue;
        if (!synth) synth.emplace();
        const auto aligned = alignText(*synth, entry.path(), readTextFile(*words), o.voice, base);
        if (aligned.fellBack || !aligned.warnings.empty()) {
            std::cerr << "lipsync calibrate: skipped " << entry.path().string() << ": "
                      << (aligned.warnings.empty() ? "not aligned" : aligned.warnings.front())
                      << '\n';
            continue;
        }
        trainer.addUtterance(dsp::analyzeFrames(entry.path(), analysis), aligned.schedule);
        for (const auto& seg : aligned.schedule)
            if (seg.phoneme != "sil") addOnce(recorded, seg.phoneme);
    }
}

void runCalibrate(const CalibrateOptions& o) {
    const auto& set = PhonemeSet::common();
    auto base = o.base.empty() ? dsp::TemplateSet::loadDefault()
                               : dsp::TemplateSet::load(findDataFile(o.base));
    dsp::TrainingOptions training;
    training.analysis = base.analysis;
    training.clustersPerClass = o.clusters;
    training.minFramesPerCluster = 10;  // a second of held sound is plenty for one speaker
    // Half a minute of one voice is too little for a network: the base's stay.
    training.jawHiddenUnits = 0;
    training.classHiddenUnits = 0;
    dsp::TemplateTrainer trainer(training, set);
    if (!std::filesystem::is_directory(o.folder)) throw InputError(o.folder + ": not a folder");
    std::vector<std::string> recorded;
    addReadSpeech(o, base, trainer, training.analysis, recorded);
    for (const auto& entry : std::filesystem::directory_iterator(o.folder)) {
        if (!isAudio(entry.path()) || wordsBeside(entry.path())) continue;
        const auto cls = classOfFile(entry.path());
        if (!set.find(cls)) {
            std::cerr
                << "lipsync calibrate: skipped " << entry.path().string() << ": '" << cls
                << "' is not a phoneme class (name files after a class: aa.wav, bmp.wav...)\n";
            continue;
        }
        trainer.addSustained(dsp::analyzeFrames(entry.path(), training.analysis), cls);
        addOnce(recorded, cls);
    }
    if (recorded.empty())
        throw InputError(o.folder +
                         ": no recordings named after a phoneme class, and none with its words "
                         "beside it (NAME.wav + NAME.txt)");
    const auto own = trainer.build("calibration");
    for (const auto& cls : own.classes) {
        auto it = std::find_if(base.classes.begin(), base.classes.end(),
                               [&](const auto& c) { return c.phoneme == cls.phoneme; });
        if (it != base.classes.end())
            *it = cls;
        else
            base.classes.push_back(cls);
        std::cerr << "lipsync calibrate: " << cls.phoneme << ": " << cls.frames << " frames, "
                  << cls.spectra.size() << " template(s)\n";
    }
    for (const auto& cls : recorded)
        if (trainer.frames(cls) < training.minFramesPerCluster)
            std::cerr << "lipsync calibrate: warning: " << cls
                      << ": too little steady sound; kept the base templates\n";
    base.description = "calibrated from " + o.folder + " over " +
                       (o.base.empty() ? std::string("the default set") : o.base);
    base.save(o.output);
    std::cerr << "lipsync calibrate: wrote " << o.output << '\n';
}
}  // namespace

void addCalibrateCommand(CLI::App& app) {
    auto o = std::make_shared<CalibrateOptions>();
    auto* cmd = app.add_subcommand(
        "calibrate",
        "Build a speaker's templates from recordings of sustained sounds named after their class "
        "(aa.wav, ih.wav, w.wav, bmp.wav, ...) or of read speech with its words beside each "
        "(NAME.wav + NAME.txt, aligned on them; half a minute is enough)");
    cmd->add_option("folder", o->folder, "Folder of recordings")->required();
    cmd->add_option("-o,--output", o->output, "Template file to write (JSON)")->required();
    cmd->add_option("--base", o->base,
                    "Templates for the classes not recorded (default: shipped set)");
    cmd->add_option("--voice", o->voice, "espeak-ng voice that reads the words of read speech")
        ->capture_default_str();
    cmd->add_option("--clusters", o->clusters, "Cluster means per recorded class")
        ->check(CLI::Range(1, 8))
        ->capture_default_str();
    cmd->callback([o] { runCalibrate(*o); });
}

}  // namespace lipsyncd::cli
