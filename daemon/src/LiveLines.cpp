// `line`: the performer says a line of the script live. The microphone's sound from the cue on
// is kept (LiveMode) until the next line, `line` without words, or `live off`; then the worker
// aligns the line's words on it and the frames it placed teach the show's voice, as a file
// played with its words does. The next line is heard on what the lines before it taught.
#include "DaemonCore.hpp"
#include "ShowSpeaker.hpp"

namespace lipsyncd::daemon {

using nlohmann::json;

json Daemon::Impl::line(const json& r) {
    if (!live)
        return {{"ok", false},
                {"error", "line: live input is off (`live on` first): a line is heard live"}};
    if (!setup->clips->speaker())
        return {{"ok", false},
                {"error", "line: adapt_speaker is off in the config: nothing would learn it"}};
    if (!r.contains("text"))
        return {{"ok", true}, {"line", nullptr}, {"learning", learnLine(live->endLine())}};
    const auto& text = r["text"].get_ref<const std::string&>();
    if (text.find_first_not_of(" \t\r\n") == std::string::npos)
        return {{"ok", false}, {"error", "line: \"text\" is blank (no text: the line is over)"}};
    checkText(text, setup->config.maxTextBytes, "line");
    const auto learning = learnLine(live->beginLine(text, setup->config.maxClipSeconds));
    status("live line " + shownLine(text));
    return {{"ok", true}, {"line", text}, {"learning", learning}};
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
