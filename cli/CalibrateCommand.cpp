// lipsync calibrate: a speaker's own templates, on top of a base set for the classes not heard,
// from a few sustained sounds (aa.wav, ih.wav, bmp.wav, ...) or from read speech with its words
// (NAME.wav + NAME.txt: the known-script aligner labels the frames). With read speech it also
// chooses the speaker's vocal-tract-length warp (AnalysisConfig::warp), moves the base set's
// templates toward the speaker's frames (SpeakerAdaptation, the service's show voice) rather
// than replacing the classes heard, and trains the set's class and jaw networks further on them.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/tts.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "Commands.hpp"
#include "Corpus.hpp"
#include "NumberOption.hpp"
#include "Output.hpp"

namespace lipsyncd::cli {

namespace {
struct CalibrateOptions {
    std::string folder;
    std::string output;
    std::string base;
    std::string voice = "en-us";
    int clusters = 2;           // sustained sounds: cluster means per class
    float priorFrames = 10;     // read speech: what a base template's mean is worth, in frames
    std::string warp = "auto";  // auto (chosen on read speech), or a fixed value
    // Read speech: passes training the networks further on the speaker's frames, at this Adam
    // step size (a tenth of the base's). Chosen on the six tune voices, each calibrated on 5 and
    // on 150 of its files and scored on others (docs/measurements.md, "Calibration trains the
    // networks"): 4 passes at 1e-4 gained 8.6 points of score from the audio alone and 2.1
    // aligned with 150 files and was even with 5; faster or longer training gained more from
    // the audio alone and lost closures aligned (3e-4: +6.4 / −5.1; 8 passes: +10.1 / −6.3).
    int networkEpochs = 4;
    float networkRate = 1e-4f;
};

// The warps tried, around none: ±15 % spans adult vocal tracts against a mixed set's (Lee &
// Rose 1996 search 0.88..1.12 for one sex's models; ours are trained on men and women).
constexpr double kWarps[] = {0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.15};
// The least warp whose agreement (visual groups, 0..1, averaged with its neighbours') lies within
// this of the best wins, so a warp must beat none by more than it: half a minute of speech
// measures the agreement roughly. On festvox-ru-nsh's first 3 sentences (a dev speaker) 0.85 /
// 0.9 / 0.95 / 1 give 55.7 / 55.6 / 55.5 / 53.7 % before averaging, and 0.95 is chosen.
constexpr double kWarpMargin = 0.01;

// A recording with its words, aligned on them.
struct ReadRecording {
    std::filesystem::path audio;
    std::string words;  // NAME.txt beside it
    PhonemeSchedule schedule;
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

double parseWarp(const std::string& text) {
    std::size_t used = 0;
    double w = 0;
    try {
        w = std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    using dsp::AnalysisConfig;  // the set's own bounds: a warp it would refuse is refused here
    static_assert(AnalysisConfig::kMinWarp == 0.7 && AnalysisConfig::kMaxWarp == 1.4,
                  "the message and --help name the bounds");
    if (used != text.size() || !(w >= AnalysisConfig::kMinWarp && w <= AnalysisConfig::kMaxWarp))
        throw InputError("--warp: expected 'auto' or a number 0.7..1.4, got '" + text + "'");
    return w;
}

bool isAudio(const std::filesystem::path& file) {
    const auto ext = file.extension().string();
    return ext == ".wav" || ext == ".flac" || ext == ".ogg";
}

// Every 20th of a long run (20 recordings or more): "aligned 40 of 310 recordings".
void reportProgress(const char* done, std::size_t i, std::size_t total) {
    if (total >= 20 && i % 20 == 0 && i > 0)
        std::cerr << "lipsync calibrate: " << done << ' ' << i << " of " << total
                  << " recordings\n";
}

// Read speech: every recording with its words beside it (NAME.txt), aligned on them (on the base
// set, unwarped). A file with a word the aligner could not place is left out: its schedule there
// would be the front end's own guess, and calibrating on that teaches the templates their own
// mistakes.
// `synth` is started only when there are words to read (espeak-ng allows one per process).
std::vector<ReadRecording> alignReadSpeech(const CalibrateOptions& o, const dsp::TemplateSet& base,
                                           std::optional<EspeakSynthesizer>& synth) {
    std::vector<std::pair<std::filesystem::path, std::filesystem::path>> files;  // audio, words
    for (const auto& entry : std::filesystem::directory_iterator(o.folder))
        if (isAudio(entry.path()))
            if (const auto words = wordsBeside(entry.path()))
                files.emplace_back(entry.path(), *words);
    std::sort(files.begin(), files.end());
    std::vector<ReadRecording> read;
    for (std::size_t i = 0; i < files.size(); ++i) {
        const auto& [audio, words] = files[i];
        reportProgress("aligned", i, files.size());
        if (!synth) synth.emplace();
        const auto skip = [&](const std::string& why) {
            std::cerr << "lipsync calibrate: skipped " << audio.string() << ": " << why << '\n';
        };
        auto text = readTextFile(words);
        try {
            const auto aligned = alignText(*synth, audio, text, o.voice, base);
            if (aligned.fellBack || !aligned.warnings.empty()) {
                skip(aligned.warnings.empty() ? "not aligned" : aligned.warnings.front());
                continue;
            }
            read.push_back({audio, std::move(text), aligned.schedule});
        } catch (const InputError& e) {  // words the voice cannot read, say: the others serve
            skip(words.string() + ": " + e.what());
        }
    }
    return read;
}

// How often the front end, from the audio alone, hears the visual group the alignment placed
// (0..1, over every frame of the recordings), with the base set read at `warp`.
double agreementAt(double warp, const std::vector<ReadRecording>& read, dsp::TemplateSet base) {
    base.analysis.warp = warp;
    dsp::ScheduleScore score;
    for (const auto& r : read)
        score.add(dsp::scoreSchedule(dsp::analyzeFile(r.audio, base, PhonemeSet::common()).schedule,
                                     r.schedule, PhonemeSet::common()));
    return score.groupAccuracy();
}

// Each value averaged with its neighbours'.
std::vector<double> neighbourMeans(const std::vector<double>& v) {
    std::vector<double> out(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
        const std::size_t from = i == 0 ? 0 : i - 1, to = std::min(v.size() - 1, i + 1);
        double sum = 0;
        for (std::size_t k = from; k <= to; ++k) sum += v[k];
        out[i] = sum / static_cast<double>(to - from + 1);
    }
    return out;
}

// The speaker's warp (Lee & Rose 1996 choose it by the likelihood of the aligned words; here the
// templates' nearest distances favour no warp whatever the voice, so the choice is by what the
// warp is for: the front end hearing, from the audio alone, the groups the words place there).
double chooseWarp(const std::vector<ReadRecording>& read, const dsp::TemplateSet& base) {
    std::vector<double> agreement;
    for (const double w : kWarps) {
        agreement.push_back(agreementAt(w, read, base));
        std::cerr << "lipsync calibrate: warp " << std::fixed << std::setprecision(2) << w
                  << ": the audio alone hears " << std::setprecision(1) << 100 * agreement.back()
                  << " % of the placed visual groups\n";
    }
    // The agreement is a smooth function of the warp; measured on half a minute it is not
    // (ktuberling-en's 15 words: 71.4 / 69.5 / 70.4 / 72.0 % at 0.9 / 0.95 / 1 / 1.05).
    agreement = neighbourMeans(agreement);
    // The least warp within kWarpMargin of the best (none, when none is), the better of two
    // as far from none.
    const double best = *std::max_element(agreement.begin(), agreement.end());
    std::optional<std::size_t> chosen;
    for (std::size_t i = 0; i < agreement.size(); ++i) {
        if (agreement[i] < best - kWarpMargin) continue;
        const double d = std::abs(kWarps[i] - 1.0);
        const double dChosen = chosen ? std::abs(kWarps[*chosen] - 1.0) : 1.0;
        if (!chosen || d < dChosen || (d == dChosen && agreement[i] > agreement[*chosen]))
            chosen = i;
    }
    return kWarps[*chosen];  // the best itself always qualifies
}

// The base set (at the chosen warp) with every template moved toward the frames of the read
// speech it is nearest to, a maximum a posteriori estimate under a prior worth `priorFrames`
// frames (Gauvain & Lee 1994): the recordings aligned again in name order, each on the voice the
// ones before taught, as the service learns a show's voice (dsp::SpeakerAdaptation). Replacing
// each class heard by a few cluster means of its frames instead, half a minute of speech (five
// prompts of each of the six tune voices) lost 14.4 points of aligned visual groups summed and
// 3.3 from the audio alone against the uncalibrated set; moving the templates gained 4.9 and 2.2
// (docs/measurements.md, "Calibration moves the templates").
// Each recording's schedule is replaced by this alignment's, on the voice the ones before taught.
dsp::TemplateSet adaptToReadSpeech(const CalibrateOptions& o, std::vector<ReadRecording>& read,
                                   const dsp::TemplateSet& base, EspeakSynthesizer& synth) {
    dsp::SpeakerAdaptation voice(base);
    for (std::size_t i = 0; i < read.size(); ++i) {
        auto& r = read[i];
        reportProgress("aligned again, on the voice learnt so far:", i, read.size());
        auto aligned = alignText(synth, r.audio, r.words, o.voice, base, {}, {}, {}, std::nullopt,
                                 true, &voice);
        if (!aligned.fellBack && aligned.warnings.empty()) r.schedule = std::move(aligned.schedule);
    }
    std::cerr << "lipsync calibrate: read speech: " << read.size() << " recording(s), "
              << voice.frames() << " frames learnt (prior " << o.priorFrames << " frames)\n";
    return voice.adapted(o.priorFrames);
}

// The set's networks trained further on the read speech's frames, each labelled by its
// alignment: the class network and the jaw network then hear this voice as the templates do.
dsp::TemplateSet fineTuneOnReadSpeech(const CalibrateOptions& o,
                                      const std::vector<ReadRecording>& read,
                                      const dsp::TemplateSet& set) {
    if (!set.jawNetwork && !set.classNetwork) return set;
    dsp::TemplateTrainer trainer(dsp::fineTuningOptions(set), PhonemeSet::common());
    for (const auto& r : read) {
        std::vector<std::string> warnings;
        trainer.addUtterance(dsp::analyzeFrames(r.audio, set.analysis, {}, &warnings), r.schedule);
        printWarnings("calibrate", warnings);
    }
    if (trainer.networkFrames() == 0) return set;
    std::cerr << "lipsync calibrate: networks: " << o.networkEpochs << " pass(es) over "
              << trainer.networkFrames() << " frames\n";
    return trainer.fineTuneNetworks(set, o.networkEpochs, o.networkRate);
}

void runCalibrate(const CalibrateOptions& o) {
    const auto& set = PhonemeSet::common();
    auto base = o.base.empty() ? dsp::TemplateSet::loadDefault()
                               : dsp::TemplateSet::load(findDataFile(o.base));
    if (!std::filesystem::is_directory(o.folder)) throw InputError(o.folder + ": not a folder");
    const std::optional<double> given =
        o.warp == "auto" ? std::nullopt : std::optional(parseWarp(o.warp));
    std::optional<EspeakSynthesizer> synth;
    auto read = alignReadSpeech(o, base, synth);
    const char* why = "as given";
    if (!given) why = read.empty() ? "none: no words to judge it by" : "chosen";
    base.analysis.warp = given ? *given : read.empty() ? 1.0 : chooseWarp(read, base);
    std::cerr << "lipsync calibrate: warp " << std::fixed << std::setprecision(2)
              << base.analysis.warp << " (" << why << ")\n";
    dsp::TrainingOptions training;
    training.analysis = base.analysis;
    training.clustersPerClass = o.clusters;
    training.minFramesPerCluster = 10;  // a second of held sound is plenty for one speaker
    // Half a minute of one voice is too little for a network: the base's stay.
    training.jawHiddenUnits = 0;
    training.classHiddenUnits = 0;
    if (!read.empty()) base = adaptToReadSpeech(o, read, base, *synth);
    if (!read.empty() && o.networkEpochs > 0) base = fineTuneOnReadSpeech(o, read, base);
    dsp::TemplateTrainer trainer(training, set);
    std::vector<std::string> recorded;
    for (const auto& entry : std::filesystem::directory_iterator(o.folder)) {
        if (!isAudio(entry.path()) || wordsBeside(entry.path())) continue;
        const auto cls = classOfFile(entry.path());
        if (!set.find(cls)) {
            std::cerr
                << "lipsync calibrate: skipped " << entry.path().string() << ": '" << cls
                << "' is not a phoneme class (name files after a class: aa.wav, bmp.wav...)\n";
            continue;
        }
        std::vector<std::string> warnings;
        trainer.addSustained(dsp::analyzeFrames(entry.path(), training.analysis, {}, &warnings),
                             cls);
        printWarnings("calibrate", warnings);
        addOnce(recorded, cls);
    }
    if (recorded.empty() && read.empty() && synth)  // read speech there was, none aligned
        throw InputError(o.folder +
                         ": none of its recordings with words could be aligned (each "
                         "skipped above; --voice LANG reads the words in another "
                         "language, now '" +
                         o.voice + "')");
    if (recorded.empty() && read.empty())
        throw InputError(o.folder +
                         ": no recordings named after a phoneme class, and none with its words "
                         "beside it (NAME.wav + NAME.txt)");
    const auto own = recorded.empty() ? dsp::TemplateSet{} : trainer.build("calibration");
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
        "(NAME.wav + NAME.txt, aligned on them; half a minute is enough, minutes train the "
        "networks too)");
    cmd->add_option("folder", o->folder, "Folder of recordings")->required();
    cmd->add_option("-o,--output", o->output, "Template file to write (JSON)")->required();
    cmd->add_option("--base", o->base,
                    "The set calibrated: read speech moves its templates, sustained sounds "
                    "replace their classes' (default: shipped set)");
    cmd->add_option("--voice", o->voice, "espeak-ng voice that reads the words of read speech")
        ->capture_default_str();
    cmd->add_option("--warp", o->warp,
                    "Vocal-tract-length warp of the spectrum: 'auto' chooses it on the read "
                    "speech (0.85..1.15; none without words), or a value 0.7..1.4 (1: none)")
        ->capture_default_str();
    addNumberOption(*cmd, "--clusters", o->clusters,
                    "Cluster means per class of sustained sounds (they replace the class's "
                    "templates)",
                    1, 8);
    addNumberOption(*cmd, "--prior", o->priorFrames,
                    "Read speech moves each template toward the speaker's frames nearest it; "
                    "what the template's old mean is worth, in frames (more: closer to the base)",
                    1.0f, 1000.0f);
    addNumberOption(*cmd, "--network-epochs", o->networkEpochs,
                    "Read speech also trains the set's class and jaw networks further on the "
                    "speaker's aligned frames: passes over them (0: the base's networks stay)",
                    0, 100);
    addNumberOption(*cmd, "--network-rate", o->networkRate,
                    "Step size of that training (Adam's; the base was trained at 0.001)", 1e-6f,
                    1e-2f);
    cmd->callback([o] { runCalibrate(*o); });
}

}  // namespace lipsyncd::cli
