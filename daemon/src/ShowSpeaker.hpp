// The show's voice so far. Every played file with its words teaches it (the frames the
// alignment placed: dsp::SpeakerAdaptation, the templates moved toward them and the networks
// trained further on them), and what it has learnt serves what comes next: the
// next line with words starts from it, a file without words is recognised on it, and live input
// started afterwards follows it. The worker aligns a line on a copy (alignment takes seconds;
// the loop must not wait for it) and what the copy learnt replaces the shared voice, unless a
// reset came in between. With a file (speaker_file), the voice outlives the process: read at
// start, written after each line that taught it, removed by a reset.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <lipsyncd/dsp.hpp>
#include <mutex>
#include <string>

namespace lipsyncd::daemon {

class ShowSpeaker {
  public:
    // `file` empty: in memory only. A file that cannot be read is reported through `log` and
    // the voice starts empty (the show goes on).
    ShowSpeaker(const dsp::TemplateSet& base, std::filesystem::path file,
                const std::function<void(const std::string&)>& log);

    struct Lesson {
        dsp::SpeakerAdaptation voice;  // the show's voice when the line began; the line adds to it
        std::uint64_t generation = 0;
    };
    Lesson startLesson() const;
    struct Finished {
        bool learnt = false;      // the line taught it something (and no reset came between)
        std::string saveProblem;  // the file could not be written: why
    };
    Finished finish(Lesson lesson);

    // The base templates moved toward the voice heard (the base itself before any line), under
    // the prior alignment gives a speaker carried from line to line.
    dsp::TemplateSet templates() const;
    void reset();  // forgets the voice, and removes its file

    struct Heard {
        std::size_t lines = 0;   // lines that taught it something (since start or reset)
        std::size_t frames = 0;  // frames learnt
        // Its networks trained further (AlignerConfig::speakerNetworkEpochs).
        bool networks = false;
        std::uint64_t generation = 0;  // counts the resets: (generation, lines) names a voice
    };
    Heard heard() const;
    const std::filesystem::path& file() const { return file_; }

  private:
    std::string save(const Lesson& lesson);

    const std::filesystem::path file_;
    mutable std::mutex mutex_;  // the state below
    dsp::SpeakerAdaptation voice_;
    std::uint64_t generation_ = 0;
    std::size_t lines_ = 0;
    // Held while the file is written or removed (never with mutex_ held first): a reset between
    // a line's check and its write cannot leave the file behind the voice.
    std::mutex fileMutex_;
};

}  // namespace lipsyncd::daemon
