// Fuzz target: a request sequence against the daemon's core (the null audio device, the
// terminal puppet, no hardware): each line of the input is one request. Every reply is one
// line of valid JSON with "ok", and nothing a client sends stops the daemon.
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <lipsyncd/daemon.hpp>
#include <nlohmann/json.hpp>
#include <string_view>

using namespace lipsyncd;

namespace {
daemon::Daemon& daemonCore() {
    static const auto dir = [] {
        const auto d = std::filesystem::temp_directory_path() /
                       ("lipsyncd_fuzz_control_" + std::to_string(::getpid()));
        std::filesystem::create_directories(d);
        std::ofstream(d / "lipsyncd.toml")
            << "[audio]\ndevice = \"null\"\n[mouth]\npuppet = \"terminal\"\nhardware = false\n"
            << "[live]\ndevice = \"file:/nonexistent.wav\"\n"
            << "[control]\nsocket = \"" << (d / "control.sock").string() << "\"\n"
            << "[limits]\nmax_clip_seconds = 5\nmax_text_bytes = 64\nmax_queue = 4\n";
        return d;
    }();
    static daemon::Daemon core(dir / "lipsyncd.toml");
    return core;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    auto& core = daemonCore();
    std::string_view input(reinterpret_cast<const char*>(data), size);
    for (int n = 0; n < 32 && !input.empty(); ++n) {
        const auto nl = input.find('\n');
        const std::string line(input.substr(0, nl));
        input.remove_prefix(nl == std::string_view::npos ? input.size() : nl + 1);
        const auto reply = core.answer(line);
        if (reply.empty() || reply.back() != '\n') __builtin_trap();
        const auto j = nlohmann::json::parse(reply, nullptr, false);
        if (j.is_discarded() || !j.is_object() || !j.contains("ok") || !j["ok"].is_boolean())
            __builtin_trap();
        core.tickOnce();
    }
    core.answer(R"({"cmd":"stop"})");
    core.answer(R"({"cmd":"live","on":false})");
    return 0;
}
