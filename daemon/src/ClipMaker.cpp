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

namespace lipsyncd::daemon {

struct ClipMaker::Impl {
    DaemonConfig config;
    lipsync::PoseSet poses;
    lipsync::BigramCurveSet curves;
    dsp::TemplateSet templates;
    std::vector<std::string> poseNames;

    explicit Impl(const DaemonConfig& c)
        : config(c),
          poses(lipsync::PoseSet::named(c.poses)),
          curves(c.character.empty()
                     ? lipsync::BigramCurveSet::named(c.curves, poses)
                     : lipsync::BigramCurveSet::load(findDataFile(c.character), poses)),
          templates(c.templates.empty() ? dsp::TemplateSet::loadDefault()
                                        : dsp::TemplateSet::load(findDataFile(c.templates))),
          poseNames(poses.names()) {}

    // The mouth for a schedule, opened as wide as the speech (its `levels`) is loud.
    PoseTrack animate(const PhonemeSchedule& s, const LevelTrack& levels) const {
        lipsync::RuntimeConfig rc;
        rc.outputRate = config.outputRateHz;
        auto track = config.runtime == "filter" ? lipsync::animateFilter(s, curves, poses, rc)
                                                : lipsync::animate(s, curves, poses, rc);
        lipsync::shapeByLoudness(poses, levels, track);
        return track;
    }
};

ClipMaker::ClipMaker(const DaemonConfig& config) : impl_(std::make_unique<Impl>(config)) {}
ClipMaker::~ClipMaker() = default;

const std::vector<std::string>& ClipMaker::poseNames() const {
    return impl_->poseNames;
}

namespace {
// The sound to play, decoded a block at a time straight into 16-bit samples: no float copy
// of the whole file is ever held (memory with a full queue of long clips).
std::vector<std::int16_t> decodeForPlayback(const std::filesystem::path& file,
                                            const dsp::DecodeOptions& options, int& rate) {
    auto decoder = dsp::AudioDecoder::open(file, options);
    rate = decoder.sampleRate();
    std::vector<std::int16_t> out;
    out.reserve(static_cast<std::size_t>(decoder.frames().value_or(0)));
    std::array<float, 4096> block{};
    while (const auto n = decoder.read(block))
        for (std::size_t i = 0; i < n; ++i)
            out.push_back(static_cast<std::int16_t>(
                std::lround(std::clamp(block[i], -1.0f, 1.0f) * 32767.0f)));
    return out;
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
    // analysis first, so its buffers are gone before the sound's is made.
    const auto schedule = scheduleForClip(
        synth, file, knownText, impl_->config.voice, impl_->templates, decode,
        log ? log : [](const auto&) {});
    {
        // The mouth opens as wide as the voice is loud: its samples, gone before the sound's.
        const auto voice = dsp::readAudioFile(file, decode);
        clip.weights =
            impl_->animate(schedule, dsp::measureLevels(voice.samples, voice.sampleRate));
    }
    dsp::DecodeOptions play;
    play.skipChannel = channel;
    clip.samples = decodeForPlayback(file, play, clip.rate);
    return clip;
}

Clip ClipMaker::fromText(EspeakSynthesizer& synth, const std::string& text,
                         const std::string& voice) const {
    const auto v = voice.empty() ? impl_->config.voice : voice;
    const auto speech = synth.synthesize({text, v, 0, -1});
    Clip clip;
    clip.name = "say: " + text;
    clip.rate = speech.sampleRate;
    clip.samples = speech.samples;
    clip.weights = impl_->animate(mapSchedule(speech.phonemes, espeakMapForVoice(v), nullptr),
                                  dsp::measureLevels(speech.samples, speech.sampleRate));
    return clip;
}

}  // namespace lipsyncd::daemon

namespace lipsyncd::daemon {

namespace {
// The front end streaming into the bigram runtime in its causal mode: weights for everything
// up to the last closed phoneme go out as soon as the phoneme closes.
class StreamingLive : public ClipMaker::Live {
  public:
    StreamingLive(const dsp::TemplateSet& templates, const lipsync::BigramCurveSet& curves,
                  const lipsync::PoseSet& poses, double outputRate, int rate)
        : analyzer_(templates, PhonemeSet::common(), rate),
          runtime_(curves, poses, 0, config(outputRate)),
          shaper_(poses) {
        analyzer_.onSegment([this](const PhonemeSegment& s) { runtime_.push(s, *out_); });
        // The newest frame's class stands for the phoneme still open (the segmenter has not
        // closed it yet): the mouth starts moving without waiting for the phoneme to end.
        analyzer_.onFrame([this](const dsp::StreamingAnalyzer::Frame& f) {
            openPhoneme_ = PhonemeSet::common()[static_cast<std::size_t>(f.label.phoneme)].name;
            openUntil_ = f.label.time;
            levels_[frames_++ % levels_.size()] = {f.label.time, f.label.energyDb};
        });
    }
    void push(std::span<const float> samples, PoseTrack& out) override {
        out_ = &out;
        analyzer_.push(samples);
        if (!openPhoneme_.empty()) runtime_.preview(openPhoneme_, openUntil_, out);
        shapeNewFrames(out);
    }
    double latencySeconds() const override { return analyzer_.latencySeconds(); }

  private:
    // Louder speech opens wider: each new weight frame by the level of the audio frame nearest
    // its time among the recent ones (a fixed ring: nothing allocates here).
    void shapeNewFrames(PoseTrack& out) {
        // The caller may clear the track between pushes: frames are told apart by their time.
        const std::size_t poses = out.poses.size();
        for (std::size_t f = 0; f < out.frames(); ++f) {
            const double t = out.times[f];
            if (t <= shapedUntil_) continue;
            float db = -120;
            double nearest = 1e9;
            for (const auto& l : levels_)
                if (std::abs(l.time - t) < nearest) nearest = std::abs(l.time - t), db = l.db;
            shaper_.shape(db, t - shapedUntil_,
                          std::span<float>(out.values).subspan(f * poses, poses));
            shapedUntil_ = t;
        }
    }
    static lipsync::RuntimeConfig config(double rate) {
        lipsync::RuntimeConfig c;
        c.outputRate = rate;
        return c;
    }
    dsp::StreamingAnalyzer analyzer_;
    lipsync::StreamingRuntime runtime_;
    lipsync::LoudnessShaper shaper_;
    PoseTrack* out_ = nullptr;
    std::string openPhoneme_;
    double openUntil_ = 0;
    struct Level {
        double time = -1e9;
        float db = -120;
    };
    std::array<Level, 32> levels_{};  // the last 320 ms of audio frames
    std::size_t frames_ = 0;
    double shapedUntil_ = -1e9;  // the last weight frame shaped
};
}  // namespace

std::unique_ptr<ClipMaker::Live> ClipMaker::startLive(int rate) const {
    return std::make_unique<StreamingLive>(impl_->templates, impl_->curves, impl_->poses,
                                           impl_->config.outputRateHz, rate);
}

}  // namespace lipsyncd::daemon
