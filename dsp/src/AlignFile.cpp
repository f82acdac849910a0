// Forced alignment over a file: a quick level pass for the speaking rate, then the front end
// feeding the aligner frame by frame, and the audio-only schedule wherever the words could not
// be placed (the front end's own recognition, as `lipsync analyze` gives it).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <lipsyncd/dsp.hpp>
#include <sstream>

#include "AdaptedDistances.hpp"
#include "AlignerInput.hpp"

namespace lipsyncd::dsp {

namespace {
// The level pass reads this many of its 10 ms blocks at once.
constexpr std::size_t kLevelBlocksPerRead = 64;
// Speech is what lies within this many dB of the loudest 10 ms block, and above the floor.
constexpr double kSpeechBelowPeakDb = 35, kSpeechFloorDbfs = -55;
// ... and clear of the room: the room's level is this quantile of the 10 ms blocks' levels
// (its quietest stretches; a quantile, not the minimum, so that one block of digital silence
// at a fade-in is not taken for the room), and speech lies above it by the front end's
// silence margin (ClassifierConfig). Without it a clip with a room less than 35 dB below the
// voice (short clips at -52 dBFS under a -18 dBFS word) counted wholly as speech, and the
// speaking rate came out twice too slow (clamped at kMaxTimeScale).
constexpr double kRoomQuantile = 0.05;
// The speaking rate is believed within these bounds (espeak-ng's 80..450 words per minute
// against its default 175 spans about 0.4..2.2).
constexpr double kMinTimeScale = 0.5, kMaxTimeScale = 2.0;
// Audio shorter than this fraction of the script's minimum cannot hold the words.
constexpr double kTooShortFraction = 0.8;

double scriptSeconds(std::span<const ScriptWord> script) {
    double total = 0;
    for (const auto& w : script)
        for (const auto& p : w.phonemes)
            if (p.phoneme != "sil") total += p.duration();
    return total;
}

std::string seconds(double s) {
    std::ostringstream out;
    out << std::fixed << std::setprecision(2) << s << " s";
    return out.str();
}

// Cuts [from, to) out of `base` and puts `fill`'s segments (clipped) there; both cover the
// whole file without gaps.
PhonemeSchedule splice(const PhonemeSchedule& base, const PhonemeSchedule& fill, double from,
                       double to) {
    PhonemeSchedule out;
    auto put = [&](PhonemeSegment s, double a, double b) {
        s.start = std::max(s.start, a);
        s.end = std::min(s.end, b);
        if (s.end - s.start < 1e-9) return;
        if (!out.empty() && out.back().phoneme == s.phoneme && out.back().end >= s.start - 1e-9)
            out.back().end = s.end;
        else
            out.push_back(s);
    };
    for (const auto& s : base) put(s, 0, from);
    for (const auto& s : fill) put(s, from, to);
    for (const auto& s : base) put(s, to, base.back().end);
    return out;
}

// The stretches to take from the audio-only schedule: what no word explains, and words not
// placed (from the end of the placed word before to the start of the placed word after).
std::vector<std::pair<double, double>> fallbackStretches(const Alignment& a, double duration) {
    auto stretches = a.unexplained;
    for (std::size_t i = 0; i < a.words.size(); ++i) {
        if (a.words[i].placed) continue;
        double from = 0, to = duration;
        for (std::size_t j = i; j-- > 0;)
            if (a.words[j].placed) {
                from = a.words[j].end;
                break;
            }
        for (std::size_t j = i + 1; j < a.words.size(); ++j)
            if (a.words[j].placed) {
                to = a.words[j].start;
                break;
            }
        if (to > from) stretches.emplace_back(from, to);
    }
    std::sort(stretches.begin(), stretches.end());
    std::vector<std::pair<double, double>> merged;
    for (const auto& s : stretches)
        if (!merged.empty() && s.first <= merged.back().second)
            merged.back().second = std::max(merged.back().second, s.second);
        else
            merged.push_back(s);
    return merged;
}

void warnAboutWords(AlignFileResult& r) {
    for (const auto& w : r.alignment.words)
        if (!w.placed) {
            std::ostringstream msg;
            msg << "word '" << w.text << "' ";
            if (w.end > w.start)
                msg << "placed only with confidence " << std::setprecision(2) << w.confidence
                    << " at " << seconds(w.start) << ": audio-only analysis used there";
            else
                msg << "not found in the audio (skipped by the speaker?)";
            r.warnings.push_back(msg.str());
        }
    for (const auto& [a, b] : r.alignment.unexplained)
        if (b - a >= 0.1)
            r.warnings.push_back("no word explains " + seconds(a) + " to " + seconds(b) +
                                 ": audio-only analysis used there");
}
}  // namespace

SpeechTiming measureSpeechTiming(std::span<const ScriptWord> script,
                                 const std::filesystem::path& file, const DecodeOptions& decode,
                                 const std::optional<RawFormat>& raw) {
    auto decoder = AudioDecoder::open(file, decode, raw);
    const auto blockSize = std::max<std::size_t>(1, decoder.sampleRate() / 100);
    // Read many 10 ms blocks at a time: a read is a system call for uncompressed files, and a
    // call per 10 ms block cost more than the sums.
    std::vector<float> buffer(blockSize * kLevelBlocksPerRead);
    std::vector<float> levels;  // dBFS per 10 ms: 400 bytes a second of audio
    std::int64_t samples = 0;
    for (bool end = false; !end;) {
        std::size_t got = 0;
        while (got < buffer.size()) {
            const auto n = decoder.read(std::span<float>(buffer).subspan(got));
            if (n == 0) break;
            got += n;
        }
        end = got < buffer.size();
        samples += static_cast<std::int64_t>(got);
        for (std::size_t at = 0; at < got; at += blockSize) {
            const auto block =
                std::span<const float>(buffer).subspan(at, std::min(blockSize, got - at));
            double sum = 0;
            for (const float v : block) sum += double(v) * v;
            levels.push_back(static_cast<float>(10 * std::log10(sum / block.size() + 1e-20)));
        }
    }
    SpeechTiming timing;
    timing.durationSeconds = static_cast<double>(samples) / decoder.sampleRate();
    if (levels.empty()) return timing;
    const double peak = *std::max_element(levels.begin(), levels.end());
    auto sorted = levels;
    const auto roomAt =
        sorted.begin() + static_cast<std::ptrdiff_t>(kRoomQuantile * (sorted.size() - 1));
    std::nth_element(sorted.begin(), roomAt, sorted.end());
    const double room = *roomAt + ClassifierConfig{}.silenceMarginDb;
    const double gate = std::max({peak - kSpeechBelowPeakDb, kSpeechFloorDbfs, room});
    std::size_t first = levels.size(), last = 0;
    for (std::size_t i = 0; i < levels.size(); ++i)
        if (levels[i] >= gate) {
            first = std::min(first, i);
            last = i;
        }
    const double expected = scriptSeconds(script);
    if (first > last || expected <= 0) return timing;
    const double speech = static_cast<double>(last - first + 1) * 0.01;
    timing.timeScale = std::clamp(speech / expected, kMinTimeScale, kMaxTimeScale);
    return timing;
}

// The segments of the words placed: what a voice's own templates may learn from. Stretches no
// word explains and words below the confidence floor are left out, so a wrong script teaches
// little.
PhonemeSchedule placedSegments(const Alignment& a) {
    PhonemeSchedule placed;
    std::size_t w = 0;
    for (const auto& seg : a.schedule) {
        while (w < a.words.size() && (!a.words[w].placed || a.words[w].end <= seg.start)) ++w;
        if (w == a.words.size()) break;
        if (seg.start >= a.words[w].start - 1e-6 && seg.end <= a.words[w].end + 1e-6)
            placed.push_back(seg);
    }
    return placed;
}

// The frames a second pass needs, with the first pass's gate, its distances per block of
// templates (FrameClassifier::blockDistances()) and the class network's term (networkTerm), up
// to a bound (about 830 bytes a frame: 25 MB for AlignerConfig::fileAdaptationMaxSeconds).
class KeptFrames {
  public:
    explicit KeptFrames(std::size_t limit) : limit_(limit) {}
    // Room for the frames expected, so that they are not copied as the arrays grow.
    void reserve(std::size_t frames, std::size_t blocksPerFrame, std::size_t classes) {
        frames = std::min(frames, limit_);
        frames_.reserve(frames);
        silent_.reserve(frames);
        blocks_.reserve(frames * blocksPerFrame);
        terms_.reserve(frames * classes);
    }
    void add(const FrameFeatures& frame, bool silent, std::span<const float> blocks,
             std::span<const float> term) {
        if (frames_.size() >= limit_) {
            overflow_ = true;
            return;
        }
        if (frames_.empty()) blocksPerFrame_ = blocks.size(), classes_ = term.size();
        frames_.push_back(frame);
        silent_.push_back(silent);
        blocks_.insert(blocks_.end(), blocks.begin(), blocks.end());
        terms_.insert(terms_.end(), term.begin(), term.end());
    }
    bool complete() const { return limit_ > 0 && !overflow_; }
    std::span<const FrameFeatures> frames() const { return frames_; }
    std::span<const std::uint8_t> silent() const { return silent_; }  // below the energy gate
    std::span<const float> blocks(std::size_t frame) const {
        return std::span(blocks_).subspan(frame * blocksPerFrame_, blocksPerFrame_);
    }
    std::span<const float> term(std::size_t frame) const {
        return std::span(terms_).subspan(frame * classes_, classes_);
    }

  private:
    std::size_t limit_;
    bool overflow_ = false;
    std::vector<FrameFeatures> frames_;
    std::vector<std::uint8_t> silent_;
    std::size_t blocksPerFrame_ = 0, classes_ = 0;
    std::vector<float> blocks_;  // [frame][block]
    std::vector<float> terms_;   // [frame][class]
};

// The second pass (AlignerConfig::fileAdaptationPriorFrames, Gauvain & Lee 1994): the file's
// frames again, on templates moved toward what the first pass placed (`measured`: the set the
// first pass classified with), with the first pass's share of the class network's term (it
// depends on the frame alone). The energy gate is the first pass's: it depends on the frames'
// levels alone. The first pass's verdict on each word stands: a word it left unplaced stays so,
// whatever the moved templates say (they learnt from the placed words only, and would fit a
// wrong script better the second time).
Alignment realign(const Alignment& first, const SpeakerAdaptation& own, const KeptFrames& kept,
                  const TemplateSet& measured, std::span<const ScriptWord> script,
                  const PhonemeSet& set, const AlignerConfig& config, double timeScale) {
    const auto adapted = own.adapted(config.fileAdaptationPriorFrames);
    AdaptedDistances distances(adapted, measured, set);
    ForcedAligner aligner(script, set, adapted.analysis.hopSeconds, timeScale, config);
    const auto frames = kept.frames();
    aligner.expectFrames(static_cast<std::int64_t>(frames.size()));
    std::vector<float> mixed;
    for (std::size_t i = 0; i < frames.size(); ++i)
        pushFrame(aligner, frames[i].time, distances(frames[i], kept.blocks(i)), kept.term(i),
                  config.classNetworkShare, kept.silent()[i], mixed);
    auto second = aligner.finish();
    if (!second.complete || second.words.size() != first.words.size()) return first;
    for (std::size_t i = 0; i < second.words.size(); ++i)
        second.words[i].placed = second.words[i].placed && first.words[i].placed;
    return second;
}

AlignFileResult alignFile(const std::filesystem::path& file, std::span<const ScriptWord> script,
                          const TemplateSet& templates, const PhonemeSet& set,
                          const FrontEndConfig& config, const AlignerConfig& alignerConfig,
                          const DecodeOptions& decode, const std::optional<RawFormat>& raw,
                          SpeakerAdaptation* speaker) {
    AlignFileResult r;
    SpeechTiming timing;
    if (file != "-") timing = measureSpeechTiming(script, file, decode, raw);
    r.timeScale = timing.timeScale;
    auto decoder = AudioDecoder::open(file, decode, raw);
    // A speaker carried from line to line: this line starts from the voice heard so far.
    const TemplateSet& base = speaker ? speaker->base() : templates;
    const auto start = speaker ? speaker->adaptedIfHeard(alignerConfig.speakerAdaptationPriorFrames)
                               : std::nullopt;
    const TemplateSet& first = start ? *start : base;
    auto wholeFile = config;
    wholeFile.resamplerUse = ResamplerUse::WholeFile;
    StreamingAnalyzer analyzer(first, set, decoder.sampleRate(), wholeFile);
    ForcedAligner aligner(script, set, first.analysis.hopSeconds, r.timeScale, alignerConfig);
    // The frames expected (the analyser's count can differ by its edge frames).
    const auto expected = std::llround(timing.durationSeconds / first.analysis.hopSeconds);
    if (timing.durationSeconds > 0) aligner.expectFrames(expected);
    const bool adapting = alignerConfig.fileAdaptationPriorFrames > 0 || speaker;
    KeptFrames kept(adapting ? static_cast<std::size_t>(alignerConfig.fileAdaptationMaxSeconds /
                                                        first.analysis.hopSeconds)
                             : 0);
    if (adapting) analyzer.recordBlockDistances();
    const auto room = static_cast<std::size_t>(expected) + 2;
    const float share = alignerConfig.classNetworkShare;
    std::vector<float> term(share > 0 ? set.size() : 0), mixed(term.size());
    kept.reserve(room, analyzer.blockDistances().size(), term.size());
    r.levels.db.reserve(room);
    r.levels.jaw.reserve(room);
    std::size_t speechFrames = 0;
    analyzer.onFrame([&](const StreamingAnalyzer::Frame& f) {
        const auto templates = analyzer.templateDistances();
        if (share > 0) networkTerm(templates, analyzer.distances(), term);
        pushFrame(aligner, f.label.time, templates, term, share, f.label.silent, mixed);
        if (adapting) kept.add(f.features, f.label.silent, analyzer.blockDistances(), term);
        speechFrames += !f.label.silent;
        r.levels.add(f.label.time, f.label.energyDb);
        r.levels.jaw.push_back(f.label.jaw);  // the heard jaw, at the aligned share
    });
    analyzer.onSegment([&](const PhonemeSegment& s) { r.audioOnly.push_back(s); });
    const auto total = analyzer.pushAll(decoder);
    analyzer.finish();
    r.warnings = decoder.warnings();
    r.durationSeconds = static_cast<double>(total) / decoder.sampleRate();
    if (!r.audioOnly.empty()) r.audioOnly.back().end = r.durationSeconds;
    r.alignment = aligner.finish();
    r.levels.rate = 1 / first.analysis.hopSeconds;
    if (alignerConfig.fileAdaptationPriorFrames > 0 && r.alignment.complete && kept.complete()) {
        SpeakerAdaptation own(base);
        if (speaker) own.add(*speaker);
        own.add(kept.frames(), placedSegments(r.alignment), kept.silent());
        r.alignment =
            realign(r.alignment, own, kept, first, script, set, alignerConfig, r.timeScale);
    }

    const std::string name = decoder.name();
    if (speechFrames == 0) {
        r.fellBack = true;
        r.warnings.push_back(name + ": no speech found (silence only): nothing to align");
    } else if (r.durationSeconds < kTooShortFraction * aligner.minimumSeconds()) {
        r.fellBack = true;
        r.warnings.push_back(name + ": audio (" + seconds(r.durationSeconds) +
                             ") far shorter than the words need (at least " +
                             seconds(aligner.minimumSeconds()) + "): not aligned");
    } else if (!r.alignment.complete) {
        r.fellBack = true;
        r.warnings.push_back(name + ": no alignment through the words was found");
    }
    if (r.fellBack) {
        for (auto& w : r.alignment.words) w.placed = false;
        r.warnings.push_back(name + ": audio-only analysis used for the whole file");
        r.schedule = r.audioOnly;
        return r;
    }
    if (speaker && kept.complete())
        speaker->add(kept.frames(), placedSegments(r.alignment), kept.silent());
    warnAboutWords(r);
    r.levels.aligned = true;  // (an audio-only fallback keeps the audio-only share)
    r.schedule = r.alignment.schedule;
    // Before the first frame and after the last, nothing was heard: silence, not a phoneme.
    if (!r.schedule.empty()) {
        auto& first = r.schedule.front();
        if (first.phoneme == "sil")
            first.start = 0;
        else if (first.start > 0)
            r.schedule.insert(r.schedule.begin(), {0.0, first.start, "sil", 1.0f});
        auto& last = r.schedule.back();
        if (last.phoneme == "sil")
            last.end = std::max(last.end, r.durationSeconds);
        else if (last.end < r.durationSeconds)
            r.schedule.push_back({last.end, r.durationSeconds, "sil", 1.0f});
    }
    for (const auto& [from, to] : fallbackStretches(r.alignment, r.durationSeconds))
        r.schedule = splice(r.schedule, r.audioOnly, from, to);
    return r;
}

}  // namespace lipsyncd::dsp
