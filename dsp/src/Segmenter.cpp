// Frame labels to segments. Runs of one class shorter than the class's minimum duration are
// flicker and merge into the run before them (hysteresis in time; notes/dsp.md: a 120 ms hold
// made viseme changes "markedly more natural"; phonemes need less). A run is final once the
// run after it has reached its own minimum length: nothing later can then move the boundary
// between them, so the delay is bounded by the longest minimum plus one hop. A silence is final
// only once it has ended, so its length is known when it is emitted: a short one inside speech
// is a stop's closure, not a pause (SegmenterConfig::stopClosureSeconds), at no extra delay.
#include <algorithm>
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {

Segmenter::Segmenter(const PhonemeSet& set, double hopSeconds, const SegmenterConfig& config)
    : set_(&set), hop_(hopSeconds), config_(config) {
    if (config_.stopClosureSeconds > 0) {
        const auto closure = set.find(config_.closureClass);
        if (!closure)
            throw InputError("segmenter: the stop closure class '" + config_.closureClass +
                             "' is not in the phoneme set");
        closure_ = static_cast<int>(*closure);
    }
    pending_.reserve(16);
    out_.reserve(16);
}

double Segmenter::minDuration(int phoneme) const {
    if (phoneme == static_cast<int>(set_->silence())) return config_.minSilenceSeconds;
    return (*set_)[static_cast<std::size_t>(phoneme)].vowel ? config_.minVowelSeconds
                                                            : config_.minConsonantSeconds;
}

double Segmenter::delaySeconds() const {
    return std::max(
               {config_.minVowelSeconds, config_.minConsonantSeconds, config_.minSilenceSeconds}) +
           hop_;
}

void Segmenter::emit(const Run& run, bool followed) {
    PhonemeSegment seg;
    seg.start = std::max(run.start, emittedUntil_);
    seg.end = run.end;
    const bool silence = run.phoneme == static_cast<int>(set_->silence());
    const bool stopClosure = silence && closure_ >= 0 && followed && lastWasSpeech_ &&
                             run.end - seg.start < config_.stopClosureSeconds - 1e-9;
    seg.phoneme = (*set_)[static_cast<std::size_t>(stopClosure ? closure_ : run.phoneme)].name;
    lastWasSpeech_ = !silence;
    seg.confidence = run.frames > 0 ? run.confidenceSum / run.frames : 0.0f;
    if (seg.end > seg.start) out_.push_back(std::move(seg));
    emittedUntil_ = run.end;
}

bool Segmenter::tooShort(const Run& run) const {
    return run.end - run.start < minDuration(run.phoneme) - 1e-9;
}

// Called when the run at `closed` has ended. Only that run can be flicker: every run before
// it was checked when it closed.
void Segmenter::absorbIfFlicker(std::size_t closed) {
    Run& run = pending_[closed];
    if (!tooShort(run) || pending_.size() < 2) return;
    if (closed > 0) {
        Run& before = pending_[closed - 1];
        before.end = run.end;
        pending_.erase(pending_.begin() + static_cast<std::ptrdiff_t>(closed));
        // The runs either side of the flicker may be one class: join them.
        if (closed < pending_.size() && pending_[closed].phoneme == before.phoneme) {
            before.end = pending_[closed].end;
            before.confidenceSum += pending_[closed].confidenceSum;
            before.frames += pending_[closed].frames;
            pending_.erase(pending_.begin() + static_cast<std::ptrdiff_t>(closed));
        }
    } else {
        pending_[1].start = run.start;
        pending_.erase(pending_.begin());
    }
}

void Segmenter::settle(bool final) {
    if (final && !pending_.empty()) absorbIfFlicker(pending_.size() - 1);
    std::size_t emitted = 0;
    while (pending_.size() - emitted >= 2 && !tooShort(pending_[emitted + 1]))
        emit(pending_[emitted++], true);
    for (; final && emitted < pending_.size(); ++emitted)
        emit(pending_[emitted], emitted + 1 < pending_.size());
    pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(emitted));
}

std::span<const PhonemeSegment> Segmenter::push(const FrameLabel& label) {
    out_.clear();
    int phoneme = label.phoneme;
    // Hysteresis in confidence: an unsure frame does not start a new run.
    if (!pending_.empty() && phoneme != pending_.back().phoneme &&
        label.confidence < config_.switchMargin)
        phoneme = pending_.back().phoneme;
    const double end = label.time + hop_ / 2;
    if (!pending_.empty() && pending_.back().phoneme == phoneme) {
        auto& run = pending_.back();
        run.end = end;
        run.confidenceSum += label.confidence;
        ++run.frames;
        // The run before may now be final: this one has just reached its minimum.
        if (pending_.size() >= 2) settle(false);
    } else {
        const double runStart = pending_.empty() ? emittedUntil_  // the first run starts at 0
                                                 : pending_.back().end;
        pending_.push_back({phoneme, runStart, end, label.confidence, 1});
        if (pending_.size() >= 2) absorbIfFlicker(pending_.size() - 2);
        settle(false);
    }
    return out_;
}

std::span<const PhonemeSegment> Segmenter::finish(double endTime) {
    out_.clear();
    if (!pending_.empty()) pending_.back().end = std::max(pending_.back().end, endTime);
    settle(true);
    if (!out_.empty()) out_.back().end = std::max(out_.back().end, endTime);
    return out_;
}

}  // namespace lipsyncd::dsp
