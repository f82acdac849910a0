// `line`: the performer says a line of the script live (its words, or `next`: the next line of
// the script `script` loaded). The microphone's sound from the cue on is kept (LiveMode) until
// the next line, `line` without words, or `live off`; then the worker aligns the line's words on
// it and the frames it placed teach the show's voice, as a file played with its words does. The
// next line is heard on what the lines before it taught. While the line is said, the worker
// reads its words first of all, and the mouth follows them from the cue on ([live]
// follow_lines, follow_lag): the runtime takes the line's phonemes from a fixed-lag alignment
// instead of the audio alone.
#include <sstream>

#include "DaemonCore.hpp"
#include "ShowSpeaker.hpp"

namespace lipsyncd::daemon {

using nlohmann::json;

json Daemon::Impl::line(const json& r) {
    if (!live)
        return {{"ok", false},
                {"error", "line: live input is off (`live on` first): a line is heard live"}};
    if (!setup->clips->speaker() && !setup->config.followLines)
        return {{"ok", false},
                {"error",
                 "line: adapt_speaker and follow_lines are both off in the config: its words "
                 "would neither teach the voice nor drive the mouth"}};
    const bool next = r.value("next", false);
    if (next && r.contains("text"))
        return {{"ok", false}, {"error", "line: give its text or next, not both"}};
    if (!next && !r.contains("text"))
        return {{"ok", true}, {"line", nullptr}, {"learning", learnLine(live->endLine())}};
    if (next && script.lines.empty())
        return {
            {"ok", false},
            {"error", "line: no script to take the next line from (`script --text-file` first)"}};
    if (next && script.next >= script.lines.size())
        return {{"ok", false},
                {"error", "line: all " + std::to_string(script.lines.size()) +
                              " lines of the script are said (`script` again to start over)"}};
    const auto& text = next ? script.lines[script.next] : r["text"].get_ref<const std::string&>();
    if (text.find_first_not_of(" \t\r\n") == std::string::npos)
        return {{"ok", false}, {"error", "line: \"text\" is blank (no text: the line is over)"}};
    checkText(text, setup->config.maxTextBytes, "line");
    // The line's sound is kept only for the voice to learn from.
    const double keep = setup->clips->speaker() ? setup->config.maxClipSeconds : 0;
    const bool follow = setup->config.followLines;
    const auto learning = learnLine(live->beginLine(text, keep, follow));
    if (follow) queue.read({live->line()->cue, text, setup->clips});
    status("live line " + shownLine(text));
    json reply = {{"ok", true}, {"line", text}, {"learning", learning}};
    if (next) reply["script_line"] = ++script.next;  // counted from 1; the next cue's is after
    return reply;
}

// `script`: the show's lines, for cues that say only "next" (a pedal, a show controller).
json Daemon::Impl::loadScript(const json& r) {
    if (r.contains("text")) {
        std::vector<std::string> lines;
        std::istringstream in(r["text"].get<std::string>());
        for (std::string l; std::getline(in, l);) {
            l.erase(l.find_last_not_of(" \t\r") + 1);  // (npos + 1: all of a blank line)
            if (!l.empty()) lines.push_back(l);
        }
        if (lines.empty()) return {{"ok", false}, {"error", "script: \"text\" has no line"}};
        for (const auto& l : lines) checkText(l, setup->config.maxTextBytes, "script");
        script.lines = std::move(lines);
        script.next = 0;
        status("script of " + std::to_string(script.lines.size()) + " lines");
    }
    return {{"ok", true}, {"script", scriptReply()}};
}

json Daemon::Impl::scriptReply() const {
    if (script.lines.empty()) return nullptr;
    const bool more = script.next < script.lines.size();
    return {{"lines", script.lines.size()},
            {"next", more ? json(script.next + 1) : json(nullptr)},
            {"next_text", more ? json(script.lines[script.next]) : json(nullptr)}};
}

json Daemon::Impl::learnLine(std::optional<LiveLine> over) {
    if (!over || over->samples.empty() || !setup->clips->speaker()) return nullptr;
    if (over->full)
        logWarning("live line " + shownLine(over->text) + ": longer than max_clip_seconds (" +
                   std::to_string(setup->config.maxClipSeconds) +
                   " s in the config); learnt from its start");
    const json name = over->text;
    if (!queue.learn({std::move(*over), setup->clips}))
        logWarning("live lines come faster than they are learnt: the oldest waiting is dropped");
    return name;
}

void Daemon::Impl::followLine() {
    auto read = queue.takeWordsRead();
    if (!read || !live || !live->line() || live->line()->cue != read->cue) return;
    const auto& text = live->line()->text;
    const auto name = "live line " + shownLine(text);
    if (!read->error.empty()) {
        logWarning(name + ": the mouth follows the audio alone: " + read->error);
        control->broadcast(json{{"event", "following"}, {"text", text}, {"error", read->error}});
    } else if (live->follow(read->cue, read->words)) {
        logInfo(name + ": the mouth follows its " + std::to_string(read->words.size()) + " words");
        control->broadcast(
            json{{"event", "following"}, {"text", text}, {"words", read->words.size()}});
    }
}

void Daemon::Impl::reportLines() {
    for (const auto& o : queue.takeLineOutcomes()) {
        if (!o.lesson.learnt) logWarning("live line " + shownLine(o.text) + ": " + o.lesson.detail);
        control->broadcast(json{{"event", "line"},
                                {"text", o.text},
                                {"learnt", o.lesson.learnt},
                                {"detail", o.lesson.detail}});
    }
}

}  // namespace lipsyncd::daemon
