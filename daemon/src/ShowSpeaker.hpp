// The show's voice so far. Every played file with its words teaches it (the frames the
// alignment placed: dsp::SpeakerAdaptation), and what it has learnt serves what comes next: the
// next line with words starts from it, a file without words is recognised on it, and live input
// started afterwards follows it. The worker aligns a line on a copy (alignment takes seconds;
// the loop must not wait for it) and what the copy learnt replaces the shared voice, unless a
// reset came in between.
#pragma once

#include <cstdint>
#include <lipsyncd/dsp.hpp>
#include <mutex>

namespace lipsyncd::daemon {

class ShowSpeaker {
  public:
    explicit ShowSpeaker(const dsp::TemplateSet& base);

    struct Lesson {
        dsp::SpeakerAdaptation voice;  // the show's voice when the line began; the line adds to it
        std::uint64_t generation = 0;
    };
    Lesson startLesson() const;
    // Kept unless reset() came after startLesson(); true when the line taught something.
    bool finish(Lesson lesson);

    // The base templates moved toward the voice heard (the base itself before any line), under
    // the prior alignment gives a speaker carried from line to line.
    dsp::TemplateSet templates() const;
    void reset();

    struct Heard {
        std::size_t lines = 0;   // lines that taught it something
        std::size_t frames = 0;  // frames learnt
    };
    Heard heard() const;

  private:
    mutable std::mutex mutex_;
    dsp::SpeakerAdaptation voice_;
    std::uint64_t generation_ = 0;
    std::size_t lines_ = 0;
};

}  // namespace lipsyncd::daemon
