#include "ShowSpeaker.hpp"

namespace lipsyncd::daemon {

ShowSpeaker::ShowSpeaker(const dsp::TemplateSet& base) : voice_(base) {}

ShowSpeaker::Lesson ShowSpeaker::startLesson() const {
    const std::lock_guard lock(mutex_);
    return {voice_, generation_};
}

bool ShowSpeaker::finish(Lesson lesson) {
    const std::lock_guard lock(mutex_);
    if (lesson.generation != generation_ || lesson.voice.frames() <= voice_.frames()) return false;
    voice_ = std::move(lesson.voice);
    ++lines_;
    return true;
}

dsp::TemplateSet ShowSpeaker::templates() const {
    const std::lock_guard lock(mutex_);
    if (voice_.frames() == 0) return voice_.base();
    return voice_.adapted(dsp::AlignerConfig{}.speakerAdaptationPriorFrames);
}

void ShowSpeaker::reset() {
    const std::lock_guard lock(mutex_);
    voice_ = dsp::SpeakerAdaptation(voice_.base());
    ++generation_;
    lines_ = 0;
}

ShowSpeaker::Heard ShowSpeaker::heard() const {
    const std::lock_guard lock(mutex_);
    return {lines_, voice_.frames()};
}

}  // namespace lipsyncd::daemon
