// Requests made ready to play: a file is decoded and analysed offline (ahead of playback, so a
// replayed file has no recognition latency); text is spoken by espeak-ng with its exact
// schedule. Either way the pose weights are computed before the first sample is heard.
#include <algorithm>
#include <array>
#include <cmath>
#include <lipsyncd/daemon.hpp>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/lipsync.hpp>
#include <lipsyncd/tts.hpp>
#include <optional>

#include "LiveMode.hpp"
#include "MemoryWav.hpp"
#include "ShowSpeaker.hpp"

namespace lipsyncd::daemon {

namespace {
constexpr int kMaxPlaybackRate = 48000;  // what any sound card plays; above is resampled
}  // namespace

struct ClipMaker::Impl {
    DaemonConfig config;
    lipsync::Runtime runtime;  // built as `lipsync animate` builds it
    dsp::TemplateSet templates;
    std::vector<std::string> poseNames;
    std::shared_ptr<ShowSpeaker> speaker;  // null: adapt_speaker = false

    explicit Impl(const DaemonConfig& c)
        : config(c),
          runtime(c.runtime),
          templates(dsp::TemplateSet::named(c.templates)),
          poseNames(runtime.poses().names()) {}
};

ClipMaker::ClipMaker(const DaemonConfig& config, const ClipMaker* previous,
                     const std::function<void(const std::string&)>& log) {
    try {
        impl_ = std::make_unique<Impl>(config);
    } catch (const InputError& e) {  // which key of the config named what failed to load
        throw InputError(config.source.string() + ": [mouth] " + e.what());
    }
    if (!config.adaptSpeaker) return;
    // A reload goes on with the voice learnt so far, unless what it adapts or keeps it changed.
    const auto* before = previous ? previous->impl_.get() : nullptr;
    if (before && before->speaker && before->config.templates == config.templates &&
        before->config.speakerFile == config.speakerFile)
        impl_->speaker = before->speaker;
    else
        impl_->speaker = std::make_shared<ShowSpeaker>(
            impl_->templates, config.speakerFile, log ? log : [](const std::string&) {});
}
ClipMaker::~ClipMaker() = default;

ShowSpeaker* ClipMaker::speaker() const {
    return impl_->speaker.get();
}

const std::vector<std::string>& ClipMaker::poseNames() const {
    return impl_->poseNames;
}

namespace {
// The sound to play, decoded a block at a time straight into 16-bit samples: no float copy
// of the whole file is ever held (memory with a full queue of long clips). Above 48 kHz it is
// resampled to 48 kHz: what one clip may hold is then bounded by max_clip_seconds alone.
std::vector<std::int16_t> decodeForPlayback(const std::filesystem::path& file,
                                            const dsp::DecodeOptions& options, int& rate) {
    auto decoder = dsp::AudioDecoder::open(file, options);
    rate = std::min(decoder.sampleRate(), kMaxPlaybackRate);
    std::optional<dsp::StreamResampler> resampler;
    if (rate != decoder.sampleRate()) resampler.emplace(decoder.sampleRate(), rate);
    std::vector<std::int16_t> out;
    out.reserve(static_cast<std::size_t>(static_cast<double>(decoder.frames().value_or(0)) * rate /
                                         decoder.sampleRate()) +
                1);
    const auto append = [&](std::span<const float> block) {
        for (const float v : block)
            out.push_back(
                static_cast<std::int16_t>(std::lround(std::clamp(v, -1.0f, 1.0f) * 32767.0f)));
    };
    std::array<float, 4096> block{};
    while (const auto n = decoder.read(block)) {
        const auto in = std::span<const float>(block).first(n);
        resampler ? append(resampler->process(in)) : append(in);
    }
    if (resampler) append(resampler->process({}, true));
    return out;
}
}  // namespace

namespace {
// What a line taught the show's voice, kept (and written to its file), and said. False when it
// taught nothing (no frame placed, or a reset came in between).
bool learnFrom(ShowSpeaker& speaker, const std::string& name, ShowSpeaker::Lesson lesson,
               const std::function<void(const std::string&)>& log) {
    const auto done = speaker.finish(std::move(lesson));
    if (!done.saveProblem.empty())
        log("the show's voice is not kept for a restart: " + done.saveProblem);
    if (!done.learnt) return false;
    const auto heard = speaker.heard();
    log(name + ": the show's voice learnt from " + std::to_string(heard.lines) + " line(s), " +
        std::to_string(heard.frames) + " frames");
    return true;
}
}  // namespace

Clip ClipMaker::fromFile(const std::filesystem::path& file, int channel, EspeakSynthesizer& synth,
                         const std::optional<std::string>& knownText,
                         const std::function<void(const std::string&)>& log) const {
    dsp::DecodeOptions decode;
    decode.channel = channel;
    Clip clip;
    clip.name = file.string();
    // Analysed on `channel` (the voice), played on the others (what the audience hears); the
    // analysis first, so its buffers are gone before the sound's is made. The mouth opens as
    // wide as the voice is loud: the analysis's own levels (as `lipsync analyze --weights`).
    // The show's voice (adapt_speaker) is learnt on a copy and kept once the schedule is made.
    LevelTrack levels;
    const auto say = log ? log : [](const std::string&) {};
    auto lesson = impl_->speaker ? std::optional(impl_->speaker->startLesson()) : std::nullopt;
    const auto schedule =
        scheduleForClip(synth, file, knownText, impl_->config.voice, impl_->templates, decode, say,
                        &levels, lesson ? &lesson->voice : nullptr);
    if (lesson) learnFrom(*impl_->speaker, file.string(), std::move(*lesson), say);
    clip.weights = impl_->runtime.animate(schedule, &levels);
    dsp::DecodeOptions play;
    play.skipChannel = channel;
    clip.samples = decodeForPlayback(file, play, clip.rate);
    return clip;
}

Clip ClipMaker::fromText(EspeakSynthesizer& synth, const std::string& text,
                         const std::string& voice, double maxSeconds) const {
    const auto v = voice.empty() ? impl_->config.voice : voice;
    auto speech = synth.synthesize({text, v, 0, -1, maxSeconds});
    if (speech.truncated)
        throw InputError("the speech is longer than max_clip_seconds (" +
                         std::to_string(maxSeconds) + " s in the config)");
    Clip clip;
    clip.name = "say: " + text;
    clip.rate = speech.sampleRate;
    const auto levels = dsp::measureLevels(speech.samples, speech.sampleRate);
    clip.samples = std::move(speech.samples);
    clip.weights = impl_->runtime.animate(
        mapSchedule(speech.phonemes, espeakMapForVoice(v), nullptr), &levels);
    return clip;
}

// As a played file with its words teaches the voice (fromFile), from samples kept in memory.
ClipMaker::LineLesson ClipMaker::learnFromLine(
    std::span<const float> samples, int rate, const std::string& text, EspeakSynthesizer& synth,
    const std::function<void(const std::string&)>& log) const {
    if (!impl_->speaker) return {false, "adapt_speaker is off in the config"};
    const auto say = log ? log : [](const std::string&) {};
    const auto name = "live line " + shownLine(text);
    const MemoryWav wav(samples, rate);
    auto lesson = impl_->speaker->startLesson();
    dsp::AlignFileResult r;
    try {
        r = alignText(synth, wav.path(), text, impl_->config.voice, impl_->templates, {}, {}, {},
                      std::nullopt, true, &lesson.voice);
    } catch (const InputError& e) {
        return {false, wav.named(e.what(), name)};
    }
    for (const auto& w : r.warnings) say(wav.named(w, name));
    const auto placed = std::count_if(r.alignment.words.begin(), r.alignment.words.end(),
                                      [](const dsp::AlignedWord& w) { return w.placed; });
    const auto words = std::to_string(placed) + " of " + std::to_string(r.alignment.words.size()) +
                       " words placed";
    if (r.fellBack || placed == 0) return {false, words + ": nothing learnt"};
    if (!learnFrom(*impl_->speaker, name, std::move(lesson), say))
        return {false, words + ", but nothing learnt (no frame kept, or a reset came in between)"};
    return {true, words};
}

}  // namespace lipsyncd::daemon

namespace lipsyncd::daemon {

namespace {
// The front end streaming into the bigram runtime in its causal mode: weights for everything
// up to the last closed phoneme go out as soon as the phoneme closes.
class StreamingLive : public ClipMaker::Live {
  public:
    StreamingLive(const dsp::TemplateSet& templates, const lipsync::Runtime& runtime, int rate)
        : analyzer_(templates, PhonemeSet::common(), rate),
          runtime_(runtime.streaming(0)),
          poses_(&runtime.poses()),
          shaper_(runtime.poses()),
          loudness_(runtime.spec().loudness),
          heardJaw_(runtime.spec().heardJaw) {
        analyzer_.onSegment([this](const PhonemeSegment& s) { runtime_.push(s, *out_); });
        // The newest frame's class stands for the phoneme still open (the segmenter has not
        // closed it yet): the mouth starts moving without waiting for the phoneme to end.
        analyzer_.onFrame([this](const dsp::StreamingAnalyzer::Frame& f) {
            openPhoneme_ = PhonemeSet::common()[static_cast<std::size_t>(f.label.phoneme)].name;
            openUntil_ = f.label.time;
            levels_[frames_++ % levels_.size()] = {f.label.time, f.label.energyDb, f.label.jaw};
        });
    }
    void push(std::span<const float> samples, PoseTrack& out) override {
        out_ = &out;
        analyzer_.push(samples);
        if (!openPhoneme_.empty()) runtime_.preview(openPhoneme_, openUntil_, out);
        if (loudness_ || heardJaw_) shapeNewFrames(out);
    }
    double latencySeconds() const override { return analyzer_.latencySeconds(); }

  private:
    // Each new weight frame takes the jaw heard around its time (the audio frames within 20 ms,
    // as the offline blend smooths it), then louder speech opens wider by the level of the
    // audio frame nearest its time, among the recent ones (a fixed ring: nothing allocates).
    // The newest frames have no later audio yet: their heard jaw is the frames so far.
    // A weight frame older than the ring (a long phoneme closing late) keeps its own jaw.
    void shapeNewFrames(PoseTrack& out) {
        // The caller may clear the track between pushes: frames are told apart by their time.
        const std::size_t poses = out.poses.size();
        for (std::size_t f = 0; f < out.frames(); ++f) {
            const double t = out.times[f];
            if (t <= shapedUntil_) continue;
            float db = -120;
            double nearest = 1e9, jawSum = 0;
            int jawFrames = 0;
            for (const auto& l : levels_) {
                if (std::abs(l.time - t) < nearest) nearest = std::abs(l.time - t), db = l.db;
                if (std::abs(l.time - t) <= lipsync::kHeardJawSmoothingSeconds / 2)
                    jawSum += l.jaw, ++jawFrames;
            }
            const auto weights = std::span<float>(out.values).subspan(f * poses, poses);
            if (heardJaw_ && jawFrames > 0)
                lipsync::blendHeardJaw(*poses_, jawSum / jawFrames, weights);
            if (loudness_) shaper_.shape(db, t - shapedUntil_, weights);
            shapedUntil_ = t;
        }
    }
    dsp::StreamingAnalyzer analyzer_;
    lipsync::StreamingRuntime runtime_;
    const lipsync::PoseSet* poses_;
    lipsync::LoudnessShaper shaper_;
    bool loudness_, heardJaw_;
    PoseTrack* out_ = nullptr;
    std::string openPhoneme_;
    double openUntil_ = 0;
    struct Level {
        double time = -1e9;
        float db = -120;
        float jaw = 0;  // the jaw the front end heard in the frame (dsp FrameLabel::jaw)
    };
    std::array<Level, 32> levels_{};  // the last 320 ms of audio frames
    std::size_t frames_ = 0;
    double shapedUntil_ = -1e9;  // the last weight frame shaped
};
}  // namespace

std::unique_ptr<ClipMaker::Live> ClipMaker::startLive(int rate) const {
    // Live input follows the show's voice as the lines with words before it taught it.
    if (impl_->speaker)
        return std::make_unique<StreamingLive>(impl_->speaker->templates(), impl_->runtime, rate);
    return std::make_unique<StreamingLive>(impl_->templates, impl_->runtime, rate);
}

}  // namespace lipsyncd::daemon
