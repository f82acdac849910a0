#include "StreamingLive.hpp"

#include <cmath>

namespace lipsyncd::daemon {

namespace {
const std::string& className(int c) {
    return PhonemeSet::common()[static_cast<std::size_t>(c)].name;
}
}  // namespace

StreamingLive::StreamingLive(const dsp::TemplateSet& templates, const lipsync::Runtime& runtime,
                             int rate, double followLagSeconds, const dsp::FrontEndConfig& frontEnd)
    : analyzer_(templates, PhonemeSet::common(), rate, frontEnd),
      runtime_(runtime.streaming(0)),
      poses_(&runtime.poses()),
      shaper_(runtime.poses()),
      loudness_(runtime.spec().loudness),
      heardJaw_(runtime.spec().heardJaw),
      hop_(templates.analysis.hopSeconds),
      window_(templates.analysis.windowSeconds),
      followLag_(followLagSeconds) {
    const auto ring = static_cast<std::size_t>(std::lround(kHeldSeconds / hop_));
    heldLabels_.resize(ring);
    heldDistances_.resize(ring * 2 * PhonemeSet::common().size());
    analyzer_.onSegment([this](const PhonemeSegment& s) {
        if (!follower_) feed(s);
    });
    analyzer_.onFrame([this](const dsp::StreamingAnalyzer::Frame& f) {
        openPhoneme_ = className(f.label.phoneme);
        openUntil_ = f.label.time;
        levels_[frames_++ % levels_.size()] = {f.label.time, f.label.energyDb, f.label.jaw};
        if (follower_)
            follower_->push(f.label, analyzer_.templateDistances(), analyzer_.distances());
        else if (holding_)
            hold(f);
    });
}

void StreamingLive::push(std::span<const float> samples, PoseTrack& out) {
    out_ = &out;
    analyzer_.push(samples);
    // The phoneme still open: the followed line's, or the newest frame's class.
    if (follower_ && follower_->openPhoneme() >= 0) {
        if (follower_->openUntil() > fedUntil_) {
            if (follower_->upcomingPhoneme() >= 0)
                runtime_.expect(className(follower_->upcomingPhoneme()),
                                follower_->upcomingStart());
            runtime_.preview(className(follower_->openPhoneme()), follower_->openUntil(), out);
        }
    } else if (!follower_ && !openPhoneme_.empty() && openUntil_ > fedUntil_) {
        runtime_.preview(openPhoneme_, openUntil_, out);
    }
    if (loudness_ || heardJaw_) shapeNewFrames(out);
}

// Segments from either source, in time order: each starts where the last one fed ended.
void StreamingLive::feed(PhonemeSegment segment) {
    if (segment.end <= fedUntil_) return;
    if (fedUntil_ >= 0) segment.start = fedUntil_;
    fedUntil_ = segment.end;
    if (watch_) watch_(segment);
    // Following a line, what comes after the closed phoneme is known: the one open now.
    if (follower_ && follower_->openPhoneme() >= 0)
        runtime_.expect(className(follower_->openPhoneme()), segment.end);
    runtime_.push(segment, *out_);
}

void StreamingLive::hold(const dsp::StreamingAnalyzer::Frame& f) {
    const auto classes = PhonemeSet::common().size();
    const auto at = held_++ % heldLabels_.size();
    heldLabels_[at] = f.label;
    const auto room = std::span(heldDistances_).subspan(at * 2 * classes, 2 * classes);
    const auto templates = analyzer_.templateDistances(), full = analyzer_.distances();
    std::copy(templates.begin(), templates.end(), room.begin());
    std::copy(full.begin(), full.end(), room.begin() + static_cast<std::ptrdiff_t>(classes));
}

void StreamingLive::cue(PoseTrack& out) {
    endLine(out);
    holding_ = true;
    held_ = 0;
}

// The words have come: the follower starts from the cue's frames (as many as the ring kept),
// and from now on the runtime takes the line's phonemes from it.
bool StreamingLive::follow(std::span<const dsp::ScriptWord> words, PoseTrack& out) {
    if (!holding_) return false;  // the line is over already
    out_ = &out;
    follower_.emplace(words, PhonemeSet::common(), hop_, followLag_);
    follower_->onSegment([this](const PhonemeSegment& s) { feed(s); });
    const auto classes = PhonemeSet::common().size();
    const auto ring = heldLabels_.size();
    for (std::size_t i = held_ > ring ? held_ - ring : 0; i < held_; ++i) {
        const auto at = i % ring;
        const auto d =
            std::span<const float>(heldDistances_).subspan(at * 2 * classes, 2 * classes);
        follower_->push(heldLabels_[at], d.first(classes), d.last(classes));
    }
    holding_ = false;
    return true;
}

void StreamingLive::endLine(PoseTrack& out) {
    holding_ = false;
    if (!follower_) return;
    out_ = &out;
    follower_->finish();  // the frames held back go to the runtime
    follower_.reset();
}

void StreamingLive::finish(PoseTrack& out) {
    endLine(out);
    out_ = &out;
    analyzer_.finish();
    runtime_.finish(out);
}

// Each new weight frame takes the jaw heard around its time (the audio frames within 20 ms,
// as the offline blend smooths it), then louder speech opens wider by the level of the audio
// frame nearest its time, among the recent ones (a fixed ring: nothing allocates). The newest
// frames have no later audio yet: their heard jaw is the frames so far. A weight frame older
// than the ring (a long phoneme closing late) keeps its own jaw.
void StreamingLive::shapeNewFrames(PoseTrack& out) {
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

}  // namespace lipsyncd::daemon
