#include "ShowSpeaker.hpp"

namespace lipsyncd::daemon {

ShowSpeaker::ShowSpeaker(const dsp::TemplateSet& base, std::filesystem::path file,
                         const std::function<void(const std::string&)>& log)
    : file_(std::move(file)), voice_(dsp::carriedVoice(base, {})) {
    std::error_code ec;
    if (file_.empty() || !std::filesystem::exists(file_, ec)) return;
    try {
        voice_.load(file_);
        log("the show's voice from " + file_.string() + ": " + std::to_string(voice_.frames()) +
            " frames");
    } catch (const InputError& e) {
        log(std::string(e.what()) + "; the show's voice starts again");
    }
}

ShowSpeaker::Lesson ShowSpeaker::startLesson() const {
    const std::lock_guard lock(mutex_);
    return {voice_, generation_};
}

ShowSpeaker::Finished ShowSpeaker::finish(Lesson lesson) {
    {
        const std::lock_guard lock(mutex_);
        if (lesson.generation != generation_ || lesson.voice.frames() <= voice_.frames()) return {};
    }
    Finished done;
    done.saveProblem = save(lesson);
    const std::lock_guard lock(mutex_);
    if (lesson.generation != generation_) return done;
    voice_ = std::move(lesson.voice);
    ++lines_;
    done.learnt = true;
    return done;
}

// Written unless a reset has come since the lesson began (it removed the file, or will once
// this write is done: both take the file's lock).
std::string ShowSpeaker::save(const Lesson& lesson) {
    if (file_.empty()) return {};
    const std::lock_guard fileLock(fileMutex_);
    {
        const std::lock_guard lock(mutex_);
        if (lesson.generation != generation_) return {};
    }
    try {
        lesson.voice.save(file_);
    } catch (const InputError& e) {
        return e.what();
    }
    return {};
}

dsp::TemplateSet ShowSpeaker::templates() const {
    const std::lock_guard lock(mutex_);  // (before any line: the base, as adapted() leaves it)
    return voice_.adapted(dsp::AlignerConfig{}.speakerAdaptationPriorFrames);
}

void ShowSpeaker::reset() {
    {
        const std::lock_guard lock(mutex_);
        voice_ = dsp::carriedVoice(voice_.base(), {});
        ++generation_;
        lines_ = 0;
    }
    if (file_.empty()) return;
    const std::lock_guard fileLock(fileMutex_);
    std::error_code ec;
    std::filesystem::remove(file_, ec);
}

ShowSpeaker::Heard ShowSpeaker::heard() const {
    const std::lock_guard lock(mutex_);
    return {lines_, voice_.frames(), voice_.networksTrained(), generation_};
}

}  // namespace lipsyncd::daemon
