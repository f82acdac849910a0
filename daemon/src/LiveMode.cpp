#include "LiveMode.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "ShowSpeaker.hpp"

namespace lipsyncd::daemon {

namespace {
// Which voice the show's is now: it changes with every line it learns and every reset.
std::pair<std::uint64_t, std::size_t> voiceNow(const ClipMaker& clips) {
    if (!clips.speaker()) return {0, 0};
    const auto heard = clips.speaker()->heard();
    return {heard.generation, heard.lines};
}
}  // namespace

LiveMode::LiveMode(const DaemonConfig& config, std::shared_ptr<const ClipMaker> clips, double now)
    : clips_(std::move(clips)),
      capture_(openCaptureSource(config.captureDevice, config.captureRate)),
      live_(clips_->startLive(capture_->rate())),
      voice_(voiceNow(*clips_)),
      newest_(clips_->poseNames().size()),
      started_(now) {}

std::span<const float> LiveMode::tick() {
    const auto n = capture_->read(buffer_);
    const auto heard = std::span<const float>(buffer_).first(n);
    if (line_ && !line_->full && line_->samples.capacity() > 0) {  // (none kept: no room)
        auto& kept = line_->samples;
        const auto room = kept.capacity() - kept.size();
        kept.insert(kept.end(), heard.begin(), heard.begin() + std::min(room, n));
        line_->full = n >= room;
    }
    live_->push(heard, frames_);
    if (frames_.frames() == 0) return {};
    const auto last = frames_.frame(frames_.frames() - 1);
    newest_.assign(last.begin(), last.end());  // no allocation after the first
    frames_.times.clear();                     // keep memory flat: only the newest frame matters
    frames_.values.clear();
    return newest_;
}

std::string shownLine(const std::string& text) {
    constexpr std::size_t kShown = 40;
    std::string one;
    for (const char c : text)
        if (!std::isspace(static_cast<unsigned char>(c)))
            one += c;
        else if (!one.empty() && one.back() != ' ')
            one += ' ';
    if (!one.empty() && one.back() == ' ') one.pop_back();
    return "'" + (one.size() > kShown ? one.substr(0, kShown) + "..." : one) + "'";
}

std::optional<LiveLine> LiveMode::beginLine(std::string text, double maxSeconds, bool follow) {
    auto over = endLine();
    followVoice();
    if (follow) live_->cue(frames_);
    line_.emplace();
    line_->text = std::move(text);
    line_->cue = ++cues_;
    line_->rate = capture_->rate();
    line_->samples.reserve(static_cast<std::size_t>(std::ceil(maxSeconds * line_->rate)));
    return over;
}

std::optional<LiveLine> LiveMode::endLine() {
    live_->endLine(frames_);
    return std::exchange(line_, std::nullopt);
}

bool LiveMode::follow(std::uint64_t cue, std::span<const dsp::ScriptWord> words) {
    return line_ && line_->cue == cue && live_->follow(words, frames_);
}

// A new front end only when the voice has learnt (or forgotten) something since the last one:
// a new one starts without the old one's noise floor and decoder history.
void LiveMode::followVoice() {
    const auto now = voiceNow(*clips_);
    if (now == voice_) return;
    live_ = clips_->startLive(capture_->rate());
    voice_ = now;
}

}  // namespace lipsyncd::daemon
