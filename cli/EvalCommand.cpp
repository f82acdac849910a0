// lipsync eval: how well `analyze` agrees with reference labels over a corpus, and how well a
// puppet's jaw follows the speech, per file and per speaker (the worst speaker is the figure).
#include <iomanip>
#include <iostream>
#include <lipsyncd/daemon.hpp>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/tts.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "AlignerOptions.hpp"
#include "Commands.hpp"
#include "Corpus.hpp"
#include "FrontEndOptions.hpp"
#include "GroupConfusion.hpp"
#include "Output.hpp"
#include "PuppetJaw.hpp"
#include "RuntimeOptions.hpp"
#include "UnusedWordsLog.hpp"

namespace lipsyncd::cli {

namespace {
constexpr double kFrameRate = 100;  // jaw frames per second, as the schedule score's step

struct EvalOptions {
    std::string corpus;
    std::string labels = "auto";
    std::string json;
    std::string schedules;  // --schedules DIR: each file's schedule as scored, DIR/SPEAKER/NAME.tsv
    std::string puppet = "jaw-servo", jawActuator;
    double minAccuracy = 0, minGroupAccuracy = 0;
    double minJawR = -1, minExactJawR = -1, minExactClosures = 0;
    double minClosures = 0, maxFalseClosures = 1;  // the jaw from audio (or aligned)
    bool perFile = true, jaw = true;
    // --align: each NAME.wav is aligned on the words of NAME.txt beside it (lipsync align)
    // instead of analysed from the audio alone; voices: "VOICE" for every speaker, or
    // "SPEAKER=VOICE" for one.
    bool align = false, adaptSpeaker = false;
    // --follow-lag: with --align, each file followed as the service follows a live line with
    // its words (a fixed-lag alignment this many seconds behind; negative: aligned whole).
    double followLag = -1;
    // --live: each file through the service's live path (ClipMaker::Live) instead.
    bool live = false;
    AlignerOptions aligner;
    std::vector<std::string> voices;
    FrontEndOptions frontEnd;
    RuntimeOptions runtime;
};

// The three ways a jaw can be driven, each scored against the same reference.
struct JawScores {
    lipsync::JawScore audio;     // audio → analyze (or align) → runtime → puppet
    lipsync::JawScore labels;    // reference phonemes → runtime → puppet
    lipsync::JawScore envelope;  // audio → loudness envelope follower → puppet
    void add(const JawScores& o) {
        audio.add(o.audio), labels.add(o.labels), envelope.add(o.envelope);
    }
};

struct Score {
    dsp::ScheduleScore schedule;
    JawScores jaw;
    dsp::BoundaryScore boundaries;  // with --align: the alignment's timing
    void add(const Score& o) {
        schedule.add(o.schedule), jaw.add(o.jaw), boundaries.add(o.boundaries);
    }
};

struct Row {
    std::string speaker, name;
    Score score;
};

// Everything loaded once for the whole corpus.
struct Evaluator {
    const EvalOptions& o;
    const PhonemeSet& set = PhonemeSet::common();
    dsp::TemplateSet templates = o.frontEnd.loadTemplates();
    // Built once: --transitions is a file read, and every file is analysed with the same.
    dsp::FrontEndConfig frontEndConfig = o.frontEnd.config();
    lipsync::Runtime runtime = o.runtime.load();
    std::optional<PuppetJaw> puppet;
    std::unique_ptr<EspeakSynthesizer> synth;  // --align, --adapt-speaker: reads the words
    // --adapt-speaker: each speaker's voice so far, carried from file to file.
    mutable std::map<std::string, dsp::SpeakerAdaptation> speakers;
    // --live: each speaker's service pieces (its show voice, with --adapt-speaker).
    mutable std::map<std::string, std::unique_ptr<daemon::ClipMaker>> liveMakers;
    // Files whose words could not be used: the first of each speaker told, the rest counted.
    mutable UnusedWordsLog unusedWords;

    explicit Evaluator(const EvalOptions& options) : o(options) {
        if (o.jaw) puppet.emplace(output::Puppet::named(o.puppet), o.jawActuator);
        if (o.align || o.adaptSpeaker) synth = std::make_unique<EspeakSynthesizer>();
    }

    // The pose track an envelope follower makes: its value on the jaw pose, nothing else.
    PoseTrack envelopeTrack(const LevelTrack& levels) const {
        const auto jawPose = runtime.poses().find("jaw");
        if (!jawPose)
            throw InputError("pose set '" + runtime.poses().name() + "' has no 'jaw' pose");
        PoseTrack track;
        track.poses = runtime.poses().names();
        std::vector<float> row(track.poses.size(), 0.0f);
        const auto envelope = dsp::followEnvelope(levels);
        for (std::size_t f = 0; f < envelope.size(); ++f) {
            row[*jawPose] = envelope[f];
            track.append(levels.start + static_cast<double>(f) / levels.rate, row);
        }
        return track;
    }

    // `mouth`: the weights under test (the runtime over the schedule, or the live path's).
    JawScores scoreJaws(const CorpusItem& item, const PhonemeSchedule& reference,
                        const PoseTrack& mouth, const LevelTrack& levels) const {
        const auto frames = static_cast<std::size_t>(reference.back().end * kFrameRate) + 1;
        const auto truth = lipsync::jawReference(reference, set, kFrameRate, frames);
        const auto score = [&](const PoseTrack& track) {
            return lipsync::scoreJaw(puppet->record(track, kFrameRate, frames), truth, reference,
                                     set, kFrameRate);
        };
        // The runtime opens the jaw by the levels the analysis measured, as `analyze --weights`
        // does; the envelope follower, like a jaw board, hears the audio itself.
        const auto audio = dsp::readAudioFile(item.audio, o.frontEnd.decode());
        const auto heard = dsp::measureLevels(audio.samples, audio.sampleRate, kFrameRate);
        // The labels' jaw is the exact phonemes' (as `say` gives it): not what the audio was
        // heard to say.
        auto loudnessOnly = o.live ? heard : levels;
        loudnessOnly.jaw.clear();
        return {score(mouth), score(runtime.animate(reference, &loudnessOnly)),
                score(envelopeTrack(heard))};
    }

    // The voice whose reading of the words a speaker's files are aligned with.
    std::string voiceFor(const std::string& speaker) const {
        if (auto own = ownVoice(speaker)) return *own;
        std::string voice = "en-us";
        for (const auto& v : o.voices)
            if (v.find('=') == std::string::npos) voice = v;
        return voice;
    }

    // The voice a SPEAKER=VOICE entry of --voice gives this speaker (the first), if any.
    std::optional<std::string> ownVoice(const std::string& speaker) const {
        for (const auto& v : o.voices)
            if (const auto eq = v.find('='); eq != std::string::npos && v.substr(0, eq) == speaker)
                return v.substr(eq + 1);
        return std::nullopt;
    }

    // Said with a speaker's first file whose words could not be used, when no --voice names
    // that speaker: the voice that read them, and how to give another.
    std::string voiceHint(const std::string& speaker) const {
        if (ownVoice(speaker)) return "";
        return "--voice " + speaker + "=LANG reads this speaker's words in its language";
    }

    void wordsNotUsed(const CorpusItem& item, const std::string& why) const {
        unusedWords.add(std::cerr, item.speaker, where(item), why, voiceHint(item.speaker));
    }

    // A file scored from the audio alone, its words unusable (`e` says why).
    void wordsLeftToAudio(const CorpusItem& item, const InputError& e) const {
        wordsNotUsed(item, std::string("words not used: ") + e.what() + "; audio-only analysis");
    }

    // The schedule under test and the levels the runtime opens the jaw by: aligned on the
    // words beside the file (--align), else analysed from the audio alone.
    std::pair<PhonemeSchedule, LevelTrack> schedule(const CorpusItem& item) const {
        dsp::SpeakerAdaptation* speaker = nullptr;
        if (o.adaptSpeaker) {
            auto it = speakers.find(item.speaker);
            if (it == speakers.end())
                it = speakers.emplace(item.speaker, dsp::carriedVoice(templates, o.aligner.config))
                         .first;
            speaker = &it->second;
        }
        if (!o.align) return analyse(item, speaker, true);
        if (o.followLag >= 0) {
            if (auto r = follow(item, speaker)) return std::move(*r);
        } else if (auto r = align(item, speaker)) {
            return {std::move(r->schedule), std::move(r->levels)};
        }
        return analyse(item, speaker, false);
    }

    // How messages about a file begin.
    static std::string where(const CorpusItem& item) {
        return "lipsync eval: " + item.speaker + '/' + item.name + ": ";
    }

    // The voice a speaker's earlier files taught (none: no speaker, or nothing heard yet).
    std::optional<dsp::TemplateSet> learnt(const dsp::SpeakerAdaptation* speaker) const {
        return speaker ? speaker->adaptedIfHeard(o.aligner.config.speakerAdaptationPriorFrames)
                       : std::nullopt;
    }

    // Words that cannot be aligned at all (none the voice can read, say) leave the file to the
    // audio alone, as the service does with such a file, and the run goes on.
    std::optional<dsp::AlignFileResult> align(const CorpusItem& item,
                                              dsp::SpeakerAdaptation* speaker) const {
        try {
            auto r = alignText(*synth, item.audio, readTextFile(*wordsBeside(item.audio)),
                               voiceFor(item.speaker), templates, frontEndConfig, o.aligner.config,
                               o.frontEnd.decode(), std::nullopt, o.aligner.reductions, speaker);
            for (const auto& w : r.warnings) std::cerr << where(item) << w << '\n';
            return r;
        } catch (const InputError& e) {
            wordsLeftToAudio(item, e);
            return std::nullopt;
        }
    }

    // From the audio alone; with a speaker (the service's adapt_speaker), on the voice its
    // earlier files taught, and then (`teach`: not when aligning them just failed) the file's
    // words teach it in turn, as a line played with its words does: what the service makes of
    // a file without words at that point of a show.
    std::pair<PhonemeSchedule, LevelTrack> analyse(const CorpusItem& item,
                                                   dsp::SpeakerAdaptation* speaker,
                                                   bool teach) const {
        const auto own = learnt(speaker);
        auto a = dsp::analyzeFile(item.audio, own ? *own : templates, set, frontEndConfig,
                                  o.frontEnd.decode(), std::nullopt);
        printWarnings("eval", a.warnings);
        if (teach && speaker && wordsBeside(item.audio)) align(item, speaker);
        return {std::move(a.schedule), std::move(a.levels)};
    }

    // --follow-lag: as the service follows a live line after its cue, on the voice the
    // speaker's earlier lines taught; once over, the line's words teach the voice in turn.
    // Words that cannot be read leave the file to the audio alone, as align() does.
    std::optional<std::pair<PhonemeSchedule, LevelTrack>> follow(
        const CorpusItem& item, dsp::SpeakerAdaptation* speaker) const {
        const auto own = learnt(speaker);
        try {
            auto a = followText(*synth, item.audio, readTextFile(*wordsBeside(item.audio)),
                                voiceFor(item.speaker), own ? *own : templates, o.followLag,
                                frontEndConfig, o.aligner.config, o.frontEnd.decode(),
                                o.aligner.reductions);
            printWarnings("eval", a.warnings);
            if (speaker) align(item, speaker);
            return std::pair(std::move(a.schedule), std::move(a.levels));
        } catch (const InputError& e) {
            wordsLeftToAudio(item, e);
            return std::nullopt;
        }
    }

    // --live: the service's pieces for a speaker, as lipsyncd's config makes them: the
    // templates and runtime given, the speaker's voice reading the words, and with
    // --adapt-speaker a show voice of its own.
    daemon::ClipMaker& liveMaker(const std::string& speaker) const {
        auto& maker = liveMakers[speaker];
        if (maker) return *maker;
        daemon::DaemonConfig c;
        c.hardware = false;
        c.templates = o.frontEnd.templates;
        // The front end as the options set it, not the service's defaults: a --class-bias or a
        // --min-vowel measured live must reach the live path.
        c.frontEnd = std::make_shared<const dsp::FrontEndConfig>(frontEndConfig);
        c.templateSet = std::make_shared<const dsp::TemplateSet>(templates);
        c.runtime = o.runtime.spec;
        c.voice = voiceFor(speaker);
        c.adaptSpeaker = o.adaptSpeaker;
        c.followLines = o.align;
        if (o.followLag >= 0) c.followLagSeconds = o.followLag;
        maker = std::make_unique<daemon::ClipMaker>(c);
        return *maker;
    }

    // --live: the file as a microphone brings it to the service, 10 ms at a time. With
    // --align it is cued with its words and followed; with --adapt-speaker the show voice learns
    // the line afterwards, as the service does once the next cue ends it. Returns the phonemes
    // the runtime took and the mouth it made.
    std::pair<PhonemeSchedule, PoseTrack> live(const CorpusItem& item) const {
        auto& maker = liveMaker(item.speaker);
        auto audio = dsp::readAudioFile(item.audio, o.frontEnd.decode());
        const auto seconds = static_cast<double>(audio.samples.size()) / audio.sampleRate;
        const auto words = wordsBeside(item.audio);
        const auto text = words ? readTextFile(*words) : std::string();
        auto path = maker.startLive(audio.sampleRate);
        PhonemeSchedule heard;
        path->watch([&](const PhonemeSegment& s) { heard.push_back(s); });
        PoseTrack mouth;
        mouth.poses = maker.poseNames();
        if (o.align && words) {
            path->cue(mouth);
            try {
                path->follow(maker.readLine(text, *synth), mouth);
            } catch (const InputError& e) {
                wordsNotUsed(item, std::string("words not followed: ") + e.what());
            }
        }
        const auto block = static_cast<std::size_t>(audio.sampleRate / 100);
        for (std::size_t at = 0; at < audio.samples.size(); at += block)
            path->push(std::span<const float>(audio.samples)
                           .subspan(at, std::min(block, audio.samples.size() - at)),
                       mouth);
        path->finish(mouth);
        if (!heard.empty()) heard.back().end = seconds;
        if (o.adaptSpeaker && words)
            maker.learnFromLine(audio.samples, audio.sampleRate, text, *synth);
        return {std::move(heard), std::move(mouth)};
    }

    // --schedules: the schedule scored, where `lipsync analyze -s` (or align) would write it.
    void keepSchedule(const CorpusItem& item, const PhonemeSchedule& hypothesis) const {
        const auto dir = std::filesystem::path(o.schedules) / item.speaker;
        std::error_code ec;
        std::filesystem::create_directories(dir, ec);
        withOutputStream((dir / (item.name + ".tsv")).string(),
                         [&](std::ostream& out) { writeSchedule(out, hypothesis); });
    }

    Score scoreFile(const CorpusItem& item) const {
        const auto reference = readLabels(item.labels, o.labels);
        PhonemeSchedule hypothesis;
        LevelTrack levels;
        PoseTrack mouth;
        if (o.live)
            std::tie(hypothesis, mouth) = live(item);
        else
            std::tie(hypothesis, levels) = schedule(item);
        if (!o.schedules.empty()) keepSchedule(item, hypothesis);
        Score s;
        s.schedule = dsp::scoreSchedule(hypothesis, reference, set);
        if (o.align) s.boundaries = dsp::scoreBoundaries(hypothesis, reference);
        if (puppet && !reference.empty()) {
            if (!o.live) mouth = runtime.animate(hypothesis, &levels);
            s.jaw = scoreJaws(item, reference, mouth, levels);
        }
        return s;
    }
};

std::string pct(double x) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(1) << 100 * x << '%';
    return s.str();
}
std::string fixed2(double x) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(2) << x;
    return s.str();
}

void printHeader(std::ostream& out, const std::string& first, bool jaw) {
    out << std::left << std::setw(30) << first << std::right << std::setw(7) << "frames"
        << std::setw(8) << "acc" << std::setw(8) << "group";
    if (jaw)
        out << "  | jaw r: audio labels envelope | closures: audio labels envelope"
               " | false closed: audio labels envelope";
    out << '\n';
}

void printRow(std::ostream& out, const std::string& first, const Score& s, bool jaw) {
    out << std::left << std::setw(30) << first << std::right << std::setw(7) << s.schedule.frames
        << std::setw(8) << pct(s.schedule.accuracy()) << std::setw(8)
        << pct(s.schedule.groupAccuracy());
    if (jaw) {
        const auto& j = s.jaw;
        out << "  |      " << std::setw(6) << fixed2(j.audio.r()) << std::setw(7)
            << fixed2(j.labels.r()) << std::setw(9) << fixed2(j.envelope.r()) << " |"
            << std::setw(16) << pct(j.audio.closureRate()) << std::setw(7)
            << pct(j.labels.closureRate()) << std::setw(9) << pct(j.envelope.closureRate()) << " |"
            << std::setw(20) << pct(j.audio.falseClosureRate()) << std::setw(7)
            << pct(j.labels.falseClosureRate()) << std::setw(9)
            << pct(j.envelope.falseClosureRate());
    }
    out << '\n';
}

// `jaw` (when scored): each class's mean jaw from the audio and from the labels, so that where
// the opening is lost shows per phoneme, as recall shows where the schedule is.
void printConfusion(std::ostream& out, const dsp::ScheduleScore& total, const PhonemeSet& set,
                    const JawScores* jaw) {
    // "heard": frames decided as the class over frames labelled as it, so a class the front end
    // hears too often (a sink for other classes) or too rarely shows at once: what a template
    // set's class bias (scripts/fit-class-bias.py) corrects.
    out << "per class (reference): frames, recall, heard (frames decided as it / its frames), "
        << (jaw ? "jaw (its mean over the class's frames: from audio, from the labels), " : "")
        << "most often taken for\n"
        << std::fixed;
    for (std::size_t r = 0; r < set.size(); ++r) {
        std::size_t n = 0, decided = 0, worst = r;
        for (std::size_t h = 0; h < set.size(); ++h) {
            n += total.confusion[r][h];
            decided += total.confusion[h][r];
            if (h != r && total.confusion[r][h] > (worst == r ? 0 : total.confusion[r][worst]))
                worst = h;
        }
        if (n == 0) continue;
        out << "  " << std::left << std::setw(5) << set[r].name << std::right << std::setw(7) << n
            << std::setw(8) << std::setprecision(1) << 100.0 * total.confusion[r][r] / n << '%'
            << std::setw(7) << std::setprecision(2) << static_cast<double>(decided) / n << "x";
        if (jaw)
            out << std::setw(7) << jaw->audio.meanJawOf(r) << std::setw(6)
                << jaw->labels.meanJawOf(r);
        out << std::setprecision(1);
        if (worst != r)
            out << "   " << set[worst].name << " (" << 100.0 * total.confusion[r][worst] / n
                << "%)";
        out << '\n';
    }
}

nlohmann::json jawJson(const lipsync::JawScore& j) {
    return {{"r", j.r()},
            {"closures", j.closures},
            {"closures_caught", j.closureRate()},
            {"open_frames", j.openFrames},
            {"false_closures", j.falseClosureRate()},
            {"opening_where_open", j.openingWhereOpen()}};
}

nlohmann::json boundaryJson(const dsp::BoundaryScore& b) {
    return {{"count", b.errors.size()},
            {"missed", b.missed},
            {"median_ms", 1000 * b.percentile(0.5)},
            {"p95_ms", 1000 * b.percentile(0.95)},
            {"within_20ms", b.shareWithin(0.02)},
            {"within_50ms", b.shareWithin(0.05)}};
}

nlohmann::json scoreJson(const Score& s, const EvalOptions& o) {
    nlohmann::json j{{"frames", s.schedule.frames},
                     {"accuracy", s.schedule.accuracy()},
                     {"group_accuracy", s.schedule.groupAccuracy()}};
    if (o.align) j["boundaries"] = boundaryJson(s.boundaries);
    if (o.jaw)
        j["jaw"] = {{"audio", jawJson(s.jaw.audio)},
                    {"labels", jawJson(s.jaw.labels)},
                    {"envelope", jawJson(s.jaw.envelope)}};
    return j;
}

// Each labelled class's mean jaw, from the audio and from the labels (printConfusion's columns).
nlohmann::json jawByClass(const JawScores& jaw, const PhonemeSet& set) {
    auto j = nlohmann::json::object();
    for (std::size_t c = 0; c < set.size(); ++c)
        if (c < jaw.audio.classFrames.size() && jaw.audio.classFrames[c] > 0)
            j[set[c].name] = {{"frames", jaw.audio.classFrames[c]},
                              {"audio", jaw.audio.meanJawOf(c)},
                              {"labels", jaw.labels.meanJawOf(c)}};
    return j;
}

// {labelled class: {heard class: frames}}.
nlohmann::json confusionJson(const dsp::ScheduleScore& score, const PhonemeSet& set) {
    auto j = nlohmann::json::object();
    for (std::size_t r = 0; r < set.size() && r < score.confusion.size(); ++r)
        for (std::size_t h = 0; h < set.size() && h < score.confusion[r].size(); ++h)
            if (score.confusion[r][h] > 0) j[set[r].name][set[h].name] = score.confusion[r][h];
    return j;
}

struct Report {
    std::vector<Row> files;
    std::map<std::string, Score> speakers;
    Score total;
};

nlohmann::json toJson(const Report& report, const PhonemeSet& set, const EvalOptions& o) {
    auto j = scoreJson(report.total, o);
    if (o.jaw) j["puppet"] = o.puppet;
    j["decoder"] = o.frontEnd.decoderNote();
    for (const auto& f : report.files) {
        auto row = scoreJson(f.score, o);
        row["name"] = f.name;
        row["speaker"] = f.speaker;
        j["files"].push_back(row);
    }
    for (const auto& [name, s] : report.speakers) {
        auto& speaker = j["speakers"][name];
        speaker = scoreJson(s, o);
        if (o.jaw) speaker["jaw_by_class"] = jawByClass(s.jaw, set);
        speaker["confusion"] = confusionJson(s.schedule, set);
        speaker["group_confusion"] = groupConfusionJson(GroupConfusion::of(s.schedule, set));
    }
    if (o.jaw) j["jaw_by_class"] = jawByClass(report.total.jaw, set);
    j["confusion"] = confusionJson(report.total.schedule, set);
    return j;
}

// The alignment's timing per speaker (dsp::scoreBoundaries).
void printBoundaries(std::ostream& out, const Report& report) {
    out << "\nboundaries: each labelled one against the aligned boundary nearest it between the "
           "same two classes (none within 100 ms: missed, counted at 100 ms)\n"
        << std::left << std::setw(30) << "speaker" << std::right << std::setw(11) << "boundaries"
        << std::setw(10) << "median" << std::setw(14) << "within 20 ms" << std::setw(14)
        << "within 50 ms" << std::setw(9) << "missed" << '\n';
    const auto row = [&](const std::string& name, const dsp::BoundaryScore& b) {
        const auto ms = [](double seconds) {
            std::ostringstream s;
            s << std::fixed << std::setprecision(1) << 1000 * seconds << " ms";
            return s.str();
        };
        out << std::left << std::setw(30) << name << std::right << std::setw(11) << b.errors.size()
            << std::setw(10) << ms(b.percentile(0.5)) << std::setw(14) << pct(b.shareWithin(0.02))
            << std::setw(14) << pct(b.shareWithin(0.05)) << std::setw(9) << b.missed << '\n';
    };
    for (const auto& [name, s] : report.speakers) row(name, s.boundaries);
    row("all", report.total.boundaries);
}

// The speaker with the lowest value of `figure`.
template <class F>
std::pair<std::string, double> worst(const Report& report, F figure) {
    std::pair<std::string, double> w{"", 2.0};
    for (const auto& [name, s] : report.speakers)
        if (figure(s) < w.second) w = {name, figure(s)};
    return w;
}

void printReport(std::ostream& out, const Report& report, const PhonemeSet& set,
                 const EvalOptions& o) {
    // Live, the words are followed (at the service's lag unless given), never aligned whole.
    const bool followed = o.followLag >= 0 || o.live;
    const double lagSeconds =
        o.followLag >= 0 ? o.followLag : daemon::DaemonConfig{}.followLagSeconds;
    const std::string made = followed ? " followed" : " aligned";
    const std::string lag =
        (followed ? ", lag " + std::to_string(std::lround(lagSeconds * 1000)) + " ms" : "") +
        (o.live ? ", live path" : "");
    if (o.perFile) {
        printHeader(out, "file", o.jaw);
        for (const auto& f : report.files) printRow(out, f.speaker + "/" + f.name, f.score, o.jaw);
        out << '\n';
    }
    printConfusion(out, report.total.schedule, set, o.jaw ? &report.total.jaw : nullptr);
    out << '\n';
    printHeader(out, "speaker", o.jaw);
    for (const auto& [name, s] : report.speakers) printRow(out, name, s, o.jaw);
    printRow(out, "all", report.total, o.jaw);
    if (o.align) printBoundaries(out, report);
    const auto group = worst(report, [](const Score& s) { return s.schedule.groupAccuracy(); });
    if (const auto w = report.speakers.find(group.first); w != report.speakers.end()) {
        out << '\n';
        printGroupConfusion(out,
                            (report.speakers.size() > 1 ? "visual groups of the worst speaker, "
                                                        : "visual groups of ") +
                                group.first,
                            GroupConfusion::of(w->second.schedule, set));
    }
    out << "\nfiles " << report.files.size() << ", speakers " << report.speakers.size()
        << ", frames " << report.total.schedule.frames << ": accuracy "
        << pct(report.total.schedule.accuracy()) << " (common set), "
        << pct(report.total.schedule.groupAccuracy()) << " (visual groups); worst speaker "
        << group.first << ' ' << pct(group.second)
        << (o.align ? " (" + made.substr(1) + " on the words" + lag + ")"
                    : " (from audio, " + o.frontEnd.decoderNote() + (o.live ? ", live path)" : ")"))
        << '\n';
    if (o.jaw) {
        const auto audio = worst(report, [](const Score& s) { return s.jaw.audio.r(); });
        const auto labels = worst(report, [](const Score& s) { return s.jaw.labels.r(); });
        out << "jaw through '" << o.puppet << "': r " << fixed2(report.total.jaw.audio.r())
            << (o.align ? made : " from audio") << (o.live ? " live" : "") << " (worst speaker "
            << audio.first << ' ' << fixed2(audio.second) << "), "
            << fixed2(report.total.jaw.labels.r()) << " from the labels (worst " << labels.first
            << ' ' << fixed2(labels.second) << "), envelope follower "
            << fixed2(report.total.jaw.envelope.r()) << '\n';
        // A mouth can move at the right times and still too little: r cannot see that.
        const auto opening =
            worst(report, [](const Score& s) { return s.jaw.audio.openingWhereOpen(); });
        out << "where the labels' mouth is clearly open, the jaw opens "
            << fixed2(report.total.jaw.audio.openingWhereOpen()) << " of its travel"
            << (o.align ? made : " from audio") << " (least: " << opening.first << ' '
            << fixed2(opening.second) << "), " << fixed2(report.total.jaw.labels.openingWhereOpen())
            << " from the labels\n";
    }
}

void checkFloors(const Report& report, const EvalOptions& o) {
    std::ostringstream why;
    const auto& t = report.total.schedule;
    if (t.accuracy() < o.minAccuracy || t.groupAccuracy() < o.minGroupAccuracy)
        why << "accuracy " << pct(t.accuracy()) << " / group " << pct(t.groupAccuracy())
            << " is below the floor " << pct(o.minAccuracy) << " / " << pct(o.minGroupAccuracy)
            << ". ";
    if (o.jaw) {
        const auto audio = worst(report, [](const Score& s) { return s.jaw.audio.r(); });
        const auto exact = worst(report, [](const Score& s) { return s.jaw.labels.r(); });
        const auto closures =
            worst(report, [](const Score& s) { return s.jaw.labels.closureRate(); });
        if (audio.second < o.minJawR)
            why << "jaw r " << (o.align ? "aligned " : "from audio ") << fixed2(audio.second)
                << " (" << audio.first << ") is below the floor " << fixed2(o.minJawR) << ". ";
        if (exact.second < o.minExactJawR)
            why << "jaw r from the labels " << fixed2(exact.second) << " (" << exact.first
                << ") is below the floor " << fixed2(o.minExactJawR) << ". ";
        if (closures.second < o.minExactClosures)
            why << "closures caught from the labels " << pct(closures.second) << " ("
                << closures.first << ") are below the floor " << pct(o.minExactClosures) << ". ";
        const auto caught = worst(report, [](const Score& s) { return s.jaw.audio.closureRate(); });
        const auto falseClosed =
            worst(report, [](const Score& s) { return -s.jaw.audio.falseClosureRate(); });
        const char* how = o.align ? "aligned " : "from audio ";
        if (caught.second < o.minClosures)
            why << "closures caught " << how << pct(caught.second) << " (" << caught.first
                << ") are below the floor " << pct(o.minClosures) << ". ";
        if (-falseClosed.second > o.maxFalseClosures)
            why << "false closures " << how << pct(-falseClosed.second) << " (" << falseClosed.first
                << ") are above the ceiling " << pct(o.maxFalseClosures) << ". ";
    }
    if (!why.str().empty()) throw std::runtime_error(why.str());
}

void runEval(const EvalOptions& o) {
    if (o.live && o.frontEnd.decoder.enabled && o.frontEnd.decoder.lagSeconds < 0)
        throw InputError("--live with --offline: live input is decoded at a fixed lag (--lag)");
    const Evaluator evaluator(o);
    std::vector<std::string> skipped;
    auto items = listCorpus(o.corpus, &skipped);
    if (o.align)
        std::erase_if(items, [&](const CorpusItem& item) {
            if (wordsBeside(item.audio)) return false;
            skipped.push_back(item.audio.string() + ": no words file " + item.name + ".txt");
            return true;
        });
    if (items.empty()) throw InputError(o.corpus + ": no NAME.wav with NAME.txt beside it");
    for (const auto& s : skipped) std::cerr << "lipsync eval: skipped " << s << '\n';
    Report report;
    for (std::size_t i = 0; i < items.size(); ++i) {
        if (items.size() >= 20 && i % 20 == 0)
            std::cerr << "lipsync eval: " << i << " of " << items.size() << " files\n";
        const auto& item = items[i];
        report.files.push_back({item.speaker, item.name, evaluator.scoreFile(item)});
        report.speakers[item.speaker].add(report.files.back().score);
        report.total.add(report.files.back().score);
    }
    evaluator.unusedWords.summarise(std::cerr, "lipsync eval");
    printReport(std::cout, report, evaluator.set, o);
    if (!o.json.empty())
        withOutputStream(o.json, [&](std::ostream& out) {
            out << toJson(report, evaluator.set, o).dump(1) << '\n';
        });
    checkFloors(report, o);
}
}  // namespace

void addEvalCommand(CLI::App& app) {
    auto o = std::make_shared<EvalOptions>();
    auto* cmd = app.add_subcommand(
        "eval",
        "Score 'analyze' and a puppet's jaw against reference labels, per file and per speaker "
        "(NAME.wav + NAME.lab in a folder, or in one subfolder per speaker)");
    cmd->footer(
        "The jaw is scored three ways, each driven through the puppet's actuators: from the "
        "audio (analyze → runtime), from the reference labels (exact phonemes → runtime), and by "
        "a loudness envelope follower (the built-in baseline). The reference is each labelled "
        "phoneme's jaw height (config/phonemes/common.toml) smoothed over 40 ms. r: Pearson "
        "correlation; closures: bilabial closures inside speech where the jaw closed (below "
        "15 % of its travel); false closed: frames where the reference is clearly open (above "
        "0.5) but the jaw is closed.");
    cmd->add_option("--corpus", o->corpus, "Folder of NAME.wav + NAME.lab (or SPEAKER/ folders)")
        ->required();
    cmd->add_option("--labels", o->labels,
                    "Label alphabet: auto, common, arpabet, or a map name/file")
        ->capture_default_str();
    cmd->add_option("--json", o->json, "Also write the figures as JSON ('-' for stdout)");
    cmd->add_option("--schedules", o->schedules,
                    "Also write each file's schedule, as scored (aligned with --align), to "
                    "DIR/SPEAKER/NAME.tsv: what to look at where a file scores badly");
    cmd->add_option("--puppet", o->puppet, "Puppet whose jaw is scored (name or file)")
        ->capture_default_str();
    cmd->add_option("--jaw-actuator", o->jawActuator,
                    "The puppet's jaw actuator (default: the one named 'jaw', else the first)");
    cmd->add_flag("!--no-jaw", o->jaw, "Score the schedule only, not the jaw");
    cmd->add_option("--min-accuracy", o->minAccuracy,
                    "Exit 1 when frame accuracy (0..1) falls below this")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_option("--min-group-accuracy", o->minGroupAccuracy,
                    "Exit 1 when visual-group accuracy (0..1) falls below this")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_option("--min-jaw-r", o->minJawR,
                    "Exit 1 when the worst speaker's jaw r from audio falls below this")
        ->check(CLI::Range(-1.0, 1.0));
    cmd->add_option("--min-exact-jaw-r", o->minExactJawR,
                    "Exit 1 when the worst speaker's jaw r from the labels falls below this")
        ->check(CLI::Range(-1.0, 1.0));
    cmd->add_option("--min-exact-closures", o->minExactClosures,
                    "Exit 1 when the worst speaker's closures caught from the labels (0..1) fall "
                    "below this")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_option("--min-closures", o->minClosures,
                    "Exit 1 when the worst speaker's closures caught from audio (aligned with "
                    "--align), 0..1, fall below this")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_option("--max-false-closures", o->maxFalseClosures,
                    "Exit 1 when the worst speaker's false closures from audio (aligned with "
                    "--align), 0..1, rise above this")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_flag("!--no-per-file", o->perFile, "Leave out the per-file table");
    auto* align = cmd->add_flag(
        "--align", o->align,
        "Score 'lipsync align' instead: each NAME.wav aligned on the words of NAME.txt "
        "beside it (files without one are skipped); the jaw 'audio' column is then "
        "the aligned schedule's, and each speaker's boundaries are timed against the "
        "labels' (median error, share within 20 and 50 ms, missed)");
    cmd->add_option("--voice", o->voices,
                    "With --align: the espeak-ng voice reading the words, VOICE for every "
                    "speaker or SPEAKER=VOICE for one (repeatable; default en-us)");
    auto* followLag =
        cmd->add_option("--follow-lag", o->followLag,
                        "With --align: follow each file as the service follows a live line said "
                        "after its cue (`lipsync ctl line`), each frame's class decided this many "
                        "seconds after it (a fixed-lag alignment at the speed the voice reads the "
                        "words), instead of aligning the whole file")
            ->check(CLI::Range(0.0, dsp::AlignerConfig{}.lookaheadSeconds))
            ->needs(align);
    auto* live = cmd->add_flag(
        "--live", o->live,
        "Score the service's live path instead: each file fed to lipsyncd's live input "
        "10 ms at a time (its front end, the runtime in its causal mode, the heard jaw "
        "and loudness as live), the schedule being what the runtime took; with --align "
        "each file is cued with its words and followed (at --follow-lag, default "
        "[live] follow_lag), with --adapt-speaker the service's show voice learns "
        "each line after it. Takes --templates, the front end's options (--class-bias, "
        "--lag, ...) and the runtime options, with none given running as lipsyncd runs; "
        "the aligner runs as lipsyncd runs it, and its options are refused");
    o->aligner.addTo(*cmd, "With --align");
    cmd->add_flag("--adapt-speaker", o->adaptSpeaker,
                  "Carry each speaker's voice from file to file, in name order, as over a show's "
                  "lines: each file starts from templates moved toward the frames placed in that "
                  "speaker's earlier files (aligned on their words, NAME.txt) and networks trained "
                  "further on them. Without --align "
                  "each file is analysed from the audio on that voice, then its words teach it: "
                  "the service's adapt_speaker for files played without words");
    addNumberOption(*cmd, "--speaker-network-epochs", o->aligner.config.speakerNetworkEpochs,
                    "With --adapt-speaker: each file also trains the speaker's class and jaw "
                    "networks further on its placed frames, this many passes (0: the set's "
                    "networks stay)",
                    0, 100)
        ->excludes(live);
    addNumberOption(*cmd, "--follow-silence-cost", o->aligner.config.followingSilenceInSpeechCost,
                    "With --follow-lag: cost per frame of silence where the energy gate hears "
                    "speech, when following (a partial path owes no words yet, so a pause must "
                    "cost about what a poorly fitting phoneme does)",
                    0.0, 100.0)
        ->needs(followLag)
        ->excludes(live);
    // The whole-file aligner's cost would be silently replaced by the one above.
    cmd->get_option("--silence-in-speech-cost")->excludes(followLag);
    // The live path aligns as lipsyncd does: an aligner option there would be silently lost.
    for (auto* option : o->aligner.added) option->excludes(live);
    o->frontEnd.addTo(*cmd);
    o->runtime.addTo(*cmd, false);
    cmd->callback([o] { runEval(*o); });
}

}  // namespace lipsyncd::cli
