// lipsyncd.toml, read strictly (TomlTable): a typo stops start-up with the file, line and key.
#include <cmath>
#include <lipsyncd/daemon.hpp>
#include <lipsyncd/toml_table.hpp>

namespace lipsyncd::daemon {

namespace {
double seconds(const TomlTable& t, const std::string& key, double fallback, double lo, double hi) {
    const double v = t.optNumber(key).value_or(fallback);
    if (!(v >= lo && v <= hi))
        t.fail(key, "must be within " + std::to_string(lo) + " .. " + std::to_string(hi) + " s");
    return v;
}
std::size_t count(const TomlTable& t, const std::string& key, std::size_t fallback, std::size_t lo,
                  std::size_t hi) {
    const double v = t.optNumber(key).value_or(static_cast<double>(fallback));
    if (!(v >= static_cast<double>(lo) && v <= static_cast<double>(hi) && v == std::floor(v)))
        t.fail(key,
               "must be a whole number within " + std::to_string(lo) + " .. " + std::to_string(hi));
    return static_cast<std::size_t>(v);
}
// A shipped data file by name ("facefx" in FOLDER/facefx.EXT) or a path: it must exist.
std::string dataName(const TomlTable& t, const std::string& key, const std::string& fallback,
                     const std::string& folder, const std::string& extension) {
    const auto name = t.optString(key).value_or(fallback);
    if (name.empty()) return name;
    std::string problem;
    try {
        const auto file =
            folder.empty() ? findDataFile(name) : findNamedDataFile(name, folder, extension);
        if (!std::filesystem::is_regular_file(file)) problem = file.string() + ": not a file";
    } catch (const InputError& e) {
        problem = e.what();
    }
    if (!problem.empty())
        t.fail(key,
               problem + (folder.empty() ? "" : " (a name in config/" + folder + " or a file)"));
    return name;
}
}  // namespace

DaemonConfig DaemonConfig::load(const std::filesystem::path& file) {
    DaemonConfig c;
    c.source = file;
    const auto root = TomlTable::parseFile(file);
    if (const auto audio = root.optTable("audio")) {
        c.device = audio->optString("device").value_or(c.device);
        audio->finish();
    }
    if (const auto mouth = root.optTable("mouth")) {
        c.puppet = mouth->optString("puppet").value_or(c.puppet);
        // The runtime, checked here so a wrong name stops start-up at its key and line.
        auto& r = c.runtime;
        r.poses = dataName(*mouth, "poses", r.poses, "poses", ".toml");
        r.curves = dataName(*mouth, "curves", r.curves, "curves", ".json");
        r.character = dataName(*mouth, "character", "", "", "");
        r.phonemes = mouth->optString("phonemes").value_or(r.phonemes);
        try {
            PhonemeSet::named(r.phonemes);
        } catch (const InputError& e) {
            mouth->fail("phonemes",
                        std::string("not a phoneme set (common, mandarin or a file): ") + e.what());
        }
        r.kind = mouth->optString("runtime").value_or(r.kind);
        if (r.kind != "bigram" && r.kind != "filter")
            mouth->fail("runtime", "must be \"bigram\" or \"filter\"");
        r.loudness = mouth->optBool("loudness").value_or(r.loudness);
        c.templates = dataName(*mouth, "templates", "", "templates", ".json");
        c.voice = mouth->optString("voice").value_or(c.voice);
        c.adaptSpeaker = mouth->optBool("adapt_speaker").value_or(c.adaptSpeaker);
        c.speakerFile = mouth->optString("speaker_file").value_or("");
        if (mouth->optNumber("lead"))
            mouth->fail("lead", "belongs to the puppet file now (lead = SECONDS: its servo lag)");
        c.syncOffsetSeconds = seconds(*mouth, "sync_offset", 0, -2, 2);
        c.hardware = mouth->optBool("hardware").value_or(true);
        c.record = mouth->optString("record").value_or("");
        c.terminal = mouth->optBool("terminal").value_or(false);
        const double rate = mouth->optNumber("output_rate").value_or(r.config.outputRate);
        if (!(rate >= 10 && rate <= 1000))
            mouth->fail("output_rate", "must be within 10 .. 1000 Hz");
        r.config.outputRate = rate;
        mouth->finish();
    }
    if (const auto live = root.optTable("live")) {
        c.captureDevice = live->optString("device").value_or(c.captureDevice);
        const double rate = live->optNumber("rate").value_or(16000);
        if (!(rate >= 8000 && rate <= 96000)) live->fail("rate", "must be within 8000 .. 96000 Hz");
        c.captureRate = static_cast<int>(rate);
        c.followLines = live->optBool("follow_lines").value_or(c.followLines);
        // (Beyond a second a mouth reads as out of step with the voice.)
        c.followLagSeconds = seconds(*live, "follow_lag", c.followLagSeconds, 0, 1);
        live->finish();
    }
    if (const auto control = root.optTable("control")) {
        c.socket = control->optString("socket").value_or(c.socket.string());
        const auto mode = control->optString("mode").value_or("0660");
        try {
            std::size_t used = 0;
            c.socketMode = static_cast<unsigned>(std::stoul(mode, &used, 8));
            if (used != mode.size() || c.socketMode > 0777) throw std::invalid_argument(mode);
        } catch (const std::exception&) {
            control->fail("mode", "must be an octal file mode such as \"0660\"");
        }
        c.maxClients = count(*control, "max_clients", c.maxClients, 1, 1000);
        control->finish();
    }
    if (const auto limits = root.optTable("limits")) {
        c.maxClipSeconds = seconds(*limits, "max_clip_seconds", c.maxClipSeconds, 0.1, 3600);
        c.maxTextBytes = count(*limits, "max_text_bytes", c.maxTextBytes, 1, 16384);
        c.maxQueue = count(*limits, "max_queue", c.maxQueue, 1, 1000);
        limits->finish();
    }
    root.finish();
    return c;
}

}  // namespace lipsyncd::daemon
