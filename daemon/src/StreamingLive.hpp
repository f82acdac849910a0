// The live path: the front end streaming into the bigram runtime in its causal mode. Weights
// for everything up to the last closed phoneme go out as soon as the phoneme closes, and the
// newest frame's class stands for the phoneme still open. During a line whose words are known
// (`line` after its cue) the runtime takes its phonemes from the words instead, followed a fixed
// lag behind the newest frame (dsp::LineFollower); before and after, from the audio alone.
#pragma once

#include <array>
#include <lipsyncd/daemon.hpp>
#include <lipsyncd/dsp.hpp>
#include <lipsyncd/lipsync.hpp>
#include <optional>
#include <string>
#include <vector>

namespace lipsyncd::daemon {

class StreamingLive : public ClipMaker::Live {
  public:
    // `followLagSeconds`: how far behind the newest frame a followed line's frames are decided.
    StreamingLive(const dsp::TemplateSet& templates, const lipsync::Runtime& runtime, int rate,
                  double followLagSeconds, const dsp::FrontEndConfig& frontEnd = {});
    void push(std::span<const float> samples, PoseTrack& out) override;
    // Following a line, a frame's phoneme is out `followLag` after the frame is (the decoder's
    // and the segmenter's delays are not on that path); else the front end's bound.
    double latencySeconds() const override {
        return follower_ ? analyzer_.resamplerDelaySeconds() + window_ + followLag_
                         : analyzer_.latencySeconds();
    }
    void cue(PoseTrack& out) override;
    bool follow(std::span<const dsp::ScriptWord> words, PoseTrack& out) override;
    void endLine(PoseTrack& out) override;
    void finish(PoseTrack& out) override;
    bool following() const override { return follower_.has_value(); }
    void watch(std::function<void(const PhonemeSegment&)> sink) override {
        watch_ = std::move(sink);
    }

    // A line's words may come this long after its cue (the worker reads them with espeak-ng):
    // the frames since the cue wait for them, in room reserved at the start.
    static constexpr double kHeldSeconds = 2.0;

  private:
    void feed(PhonemeSegment segment);
    void hold(const dsp::StreamingAnalyzer::Frame& f);
    void shapeNewFrames(PoseTrack& out);

    dsp::StreamingAnalyzer analyzer_;
    lipsync::StreamingRuntime runtime_;
    const lipsync::PoseSet* poses_;
    lipsync::LoudnessShaper shaper_;
    bool loudness_, heardJaw_;
    double hop_, window_, followLag_;
    PoseTrack* out_ = nullptr;
    std::string openPhoneme_;
    double openUntil_ = 0;
    // The runtime has had every phoneme up to here: what comes next starts here (the analyser's
    // segments and a followed line's meet without a gap or an overlap).
    double fedUntil_ = -1;
    struct Level {
        double time = -1e9;
        float db = -120;
        float jaw = 0;  // the jaw the front end heard in the frame (dsp FrameLabel::jaw)
    };
    std::array<Level, 32> levels_{};  // the last 320 ms of audio frames
    std::size_t frames_ = 0;
    double shapedUntil_ = -1e9;  // the last weight frame shaped
    // Since the cue, until the words come: each frame's label and its template and full
    // distances (a ring: the newest kHeldSeconds).
    bool holding_ = false;
    std::vector<dsp::FrameLabel> heldLabels_;
    std::vector<float> heldDistances_;  // [frame][templates, full][class]
    std::size_t held_ = 0;              // frames held since the cue (the ring keeps the newest)
    std::optional<dsp::LineFollower> follower_;
    std::function<void(const PhonemeSegment&)> watch_;
};

}  // namespace lipsyncd::daemon
