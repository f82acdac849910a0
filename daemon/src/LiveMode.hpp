// Live: capture → streaming front end → causal runtime → the mouth, with the least delay.
// A line of the script said live (`line` requests) is also kept as it is heard, so that once it
// is over its words can be aligned on it and teach the show's voice; while it is said, once the
// worker has read its words, the mouth follows them ([live] follow_lines).
#pragma once

#include <lipsyncd/daemon.hpp>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace lipsyncd::daemon {

// A line said live: its words, and the sound heard from its cue on.
struct LiveLine {
    std::string text;
    std::uint64_t cue = 0;  // counted from 1: which cue began it (the words read belong to one)
    std::vector<float> samples;  // mono, at `rate`: reserved when the line began
    int rate = 0;
    bool full = false;  // stopped at its length limit: what came after was not kept
    double seconds() const { return rate > 0 ? static_cast<double>(samples.size()) / rate : 0; }
};

// A line's words as logs and status show them: on one line, long ones cut short.
std::string shownLine(const std::string& text);

class LiveMode {
  public:
    // Opens the capture device; InputError naming it when it cannot.
    LiveMode(const DaemonConfig& config, std::shared_ptr<const ClipMaker> clips, double now);
    // What arrived since the last tick; the newest final weights frame, or an empty span when
    // none came (the mouth takes the newest: the slew limit smooths). Allocates nothing: a
    // line being heard takes the samples into the room reserved when it began.
    std::span<const float> tick();
    double started() const { return started_; }
    double frontEndLatency() const { return live_->latencySeconds(); }

    // A line begins (its words): the sound from now on is kept, at most `maxSeconds` of it;
    // with `follow`, the frames wait for its words (follow()).
    // Returns the line that was being heard, now over. Live input follows the show's voice as
    // the lines so far have taught it from here on (a new front end on it: between lines, so
    // no phoneme is cut).
    std::optional<LiveLine> beginLine(std::string text, double maxSeconds, bool follow = false);
    std::optional<LiveLine> endLine();  // the line being heard is over: it, if there was one
    const LiveLine* line() const { return line_ ? &*line_ : nullptr; }  // being heard
    // The words of the line `cue` began, read: the mouth follows them from the cue on, if that
    // line is still being heard (true).
    bool follow(std::uint64_t cue, std::span<const dsp::ScriptWord> words);
    bool following() const { return live_->following(); }

  private:
    void followVoice();

    std::shared_ptr<const ClipMaker> clips_;  // what live_ was made from lives as long as it
    std::unique_ptr<CaptureSource> capture_;
    std::unique_ptr<ClipMaker::Live> live_;
    std::pair<std::uint64_t, std::size_t> voice_;  // the show's voice live_ was made on
    PoseTrack frames_;
    std::vector<float> buffer_ = std::vector<float>(96000);
    std::vector<float> newest_;
    std::optional<LiveLine> line_;
    std::uint64_t cues_ = 0;
    double started_;
};

}  // namespace lipsyncd::daemon
