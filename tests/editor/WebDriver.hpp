// Just enough of the W3C WebDriver protocol to drive Debian's headless chromium through
// chromedriver from a test: sessions, elements, clicks, keys, pointer drags, scripts and
// screenshots. Plain HTTP and JSON (cpp-httplib's client, nlohmann::json).
#pragma once

#include <fcntl.h>
#include <httplib.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace lipsyncd::test {

// A child process with stdout and stderr in files; SIGTERM and reaped on destruction.
class ChildProcess {
  public:
    ChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& out,
                 const std::filesystem::path& err) {
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
        posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                         0644);
        posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                         0644);
        auto args = argv;
        std::vector<char*> cargs;
        for (auto& a : args) cargs.push_back(a.data());
        cargs.push_back(nullptr);
        if (posix_spawn(&pid_, args[0].c_str(), &actions, nullptr, cargs.data(), environ) != 0)
            pid_ = -1;
        posix_spawn_file_actions_destroy(&actions);
    }
    ~ChildProcess() {
        if (pid_ <= 0) return;
        ::kill(pid_, SIGTERM);
        ::waitpid(pid_, nullptr, 0);
    }
    ChildProcess(const ChildProcess&) = delete;
    ChildProcess& operator=(const ChildProcess&) = delete;
    bool started() const { return pid_ > 0; }
    bool running() const { return pid_ > 0 && ::waitpid(pid_, nullptr, WNOHANG) == 0; }

  private:
    pid_t pid_ = -1;
};

// A TCP port nobody listens on right now (the kernel's choice).
inline int freePort() {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof addr;
    ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
    ::close(fd);
    return ntohs(addr.sin_port);
}

// Polls `ready` every 50 ms until it holds or `seconds` pass.
template <typename F>
bool waitFor(F ready, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
        if (ready()) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return ready();
}

inline std::string decodeBase64(const std::string& in) {
    std::string out;
    unsigned buffer = 0;
    int bits = 0;
    for (const char c : in) {
        int v = -1;
        if (c >= 'A' && c <= 'Z')
            v = c - 'A';
        else if (c >= 'a' && c <= 'z')
            v = c - 'a' + 26;
        else if (c >= '0' && c <= '9')
            v = c - '0' + 52;
        else if (c == '+')
            v = 62;
        else if (c == '/')
            v = 63;
        if (v < 0) continue;
        buffer = (buffer << 6) | static_cast<unsigned>(v);
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out.push_back(static_cast<char>((buffer >> bits) & 0xff));
        }
    }
    return out;
}

class WebDriver {
  public:
    using json = nlohmann::json;
    static constexpr const char* kElement = "element-6066-11e4-a52e-4f735466cecf";

    explicit WebDriver(int port) : http_("127.0.0.1", port) { http_.set_read_timeout(60, 0); }
    bool up() {
        const auto r = http_.Get("/status");
        return r && r->status == 200;
    }
    // Starts the browser; the error text when it cannot.
    std::string startSession(const json& capabilities) {
        const auto r =
            http_.Post("/session", json{{"capabilities", capabilities}}.dump(), "application/json");
        if (!r) return "no answer from chromedriver";
        const auto j = json::parse(r->body, nullptr, false);
        if (r->status != 200 || j.is_discarded() || !j["value"].contains("sessionId"))
            return r->body;
        session_ = j["value"]["sessionId"];
        return "";
    }
    ~WebDriver() {
        if (!session_.empty()) http_.Delete("/session/" + session_);
    }

    json call(const std::string& method, const std::string& path,
              const json& body = json::object()) {
        const auto url = "/session/" + session_ + path;
        const auto r =
            method == "GET" ? http_.Get(url) : http_.Post(url, body.dump(), "application/json");
        if (!r) throw std::runtime_error("webdriver: no answer to " + path);
        auto j = json::parse(r->body);
        if (r->status != 200) throw std::runtime_error("webdriver " + path + ": " + r->body);
        return j["value"];
    }
    void go(const std::string& url) { call("POST", "/url", {{"url", url}}); }
    std::string find(const std::string& css) {
        return call("POST", "/element", {{"using", "css selector"}, {"value", css}})[kElement];
    }
    void click(const std::string& css) { call("POST", "/element/" + find(css) + "/click"); }
    void type(const std::string& css, const std::string& text) {
        const auto e = find(css);
        call("POST", "/element/" + e + "/clear");
        call("POST", "/element/" + e + "/value", {{"text", text}});
    }
    json script(const std::string& js, const json& args = json::array()) {
        return call("POST", "/execute/sync", {{"script", js}, {"args", args}});
    }
    // Press on the element's centre, move by (dx, dy) in steps, release.
    void drag(const std::string& css, int dx, int dy) {
        const json origin{{kElement, find(css)}};
        const json steps = json::array({
            {{"type", "pointerMove"}, {"duration", 0}, {"origin", origin}, {"x", 0}, {"y", 0}},
            {{"type", "pointerDown"}, {"button", 0}},
            {{"type", "pointerMove"},
             {"duration", 150},
             {"origin", "pointer"},
             {"x", dx / 2},
             {"y", dy / 2}},
            {{"type", "pointerMove"},
             {"duration", 150},
             {"origin", "pointer"},
             {"x", dx - dx / 2},
             {"y", dy - dy / 2}},
            {{"type", "pointerUp"}, {"button", 0}},
        });
        call("POST", "/actions",
             {{"actions", json::array({{{"type", "pointer"},
                                        {"id", "mouse"},
                                        {"parameters", {{"pointerType", "mouse"}}},
                                        {"actions", steps}}})}});
    }
    std::string screenshotPng() { return decodeBase64(call("GET", "/screenshot")); }

  private:
    httplib::Client http_;
    std::string session_;
};

}  // namespace lipsyncd::test
