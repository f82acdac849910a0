// lipsyncd as systemd runs it, for tests: a subprocess with a test NOTIFY_SOCKET, the null or
// file audio device and the recorder, and clients of its control socket.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <lipsyncd/core.hpp>
#include <lipsyncd/daemon.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>

#include "../cli/RunLipsync.hpp"

namespace lipsyncd::test {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace std::chrono_literals;

// A datagram socket standing in for systemd's notification socket.
class NotifySocket {
  public:
    explicit NotifySocket(const fs::path& path) : path_(path) {
        fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
        sockaddr_un a{};
        a.sun_family = AF_UNIX;
        std::strncpy(a.sun_path, path.c_str(), sizeof(a.sun_path) - 1);
        ::unlink(path.c_str());
        EXPECT_EQ(::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
        timeval tv{0, 200'000};
        ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    }
    ~NotifySocket() { ::close(fd_); }
    // Waits up to `timeout` for a message containing `what`; returns everything received.
    bool waitFor(const std::string& what, std::chrono::milliseconds timeout = 10s) {
        const auto end = std::chrono::steady_clock::now() + timeout;
        while (std::chrono::steady_clock::now() < end) {
            char buf[4096];
            const auto n = ::recv(fd_, buf, sizeof buf, 0);
            if (n > 0) received.emplace_back(buf, static_cast<std::size_t>(n));
            for (const auto& m : received)
                if (m.find(what) != std::string::npos) return true;
        }
        return false;
    }
    std::vector<std::string> received;

  private:
    fs::path path_;
    int fd_;
};

// The daemon's own client (as `lipsync ctl` uses it), waiting for the daemon to come up.
class Client {
  public:
    explicit Client(const fs::path& path) {
        for (int i = 0; i < 100 && !c_; ++i) {
            try {
                c_.emplace(path, 10s);  // a test fails, it does not hang
            } catch (const InputError&) {
                std::this_thread::sleep_for(50ms);
            }
        }
    }
    bool connected() const { return c_.has_value(); }
    void sendLine(const std::string& line) { sendRaw(line + "\n"); }
    void sendRaw(const std::string& bytes) {
        try {
            c_->sendRaw(bytes);
        } catch (const std::runtime_error&) {  // closed by the daemon: readLine says so
        }
    }
    // The next line; "" when the daemon closed the connection or did not answer.
    std::string readLine() {
        try {
            return c_->readLine();
        } catch (const std::runtime_error&) {
            return "";
        }
    }
    json request(const json& r) { return c_->request(r); }

  private:
    std::optional<daemon::ControlClient> c_;
};

struct DaemonProcess {
    fs::path dir = scratchDir("daemon");
    pid_t pid = -1;

    explicit DaemonProcess(const std::string& extraMouth = "", const std::string& device = "null",
                           const std::string& puppet = "terminal") {
        std::ofstream(dir / "lipsyncd.toml")
            << "[audio]\ndevice = \"" << device << "\"\n[mouth]\npuppet = \"" << puppet << "\"\n"
            << "hardware = false\nrecord = \"" << (dir / "rec.csv").string() << "\"\n"
            << extraMouth << "[control]\nsocket = \"" << (dir / "control.sock").string() << "\"\n";
    }
    // More config after the [control] section: its keys, or new sections.
    void append(const std::string& toml) const {
        std::ofstream(dir / "lipsyncd.toml", std::ios::app) << toml << "\n";
    }
    fs::path socket() const { return dir / "control.sock"; }
    std::string log() const { return slurp(dir / "stderr.log"); }
    // CPU seconds the daemon has used (user + system).
    double cpuSeconds() const {
        std::ifstream s("/proc/" + std::to_string(pid) + "/stat");
        std::string field;
        for (int i = 1; i <= 13 && s >> field; ++i) {
        }
        long user = 0, sys = 0;
        s >> user >> sys;
        return static_cast<double>(user + sys) / static_cast<double>(::sysconf(_SC_CLK_TCK));
    }
    void start() {
        ::setenv("NOTIFY_SOCKET", (dir / "notify").c_str(), 1);
        std::vector<std::string> args{LIPSYNCD_DAEMON_BIN, "--config",
                                      (dir / "lipsyncd.toml").string()};
        std::vector<char*> argv;
        for (auto& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 2, (dir / "stderr.log").c_str(),
                                         O_WRONLY | O_CREAT | O_TRUNC, 0644);
        ASSERT_EQ(posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ), 0);
        posix_spawn_file_actions_destroy(&actions);
        ::unsetenv("NOTIFY_SOCKET");
    }
    int stop(int signal = SIGTERM) {
        ::kill(pid, signal);
        int status = 0;
        ::waitpid(pid, &status, 0);
        pid = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    bool running() const {
        int status = 0;
        return pid > 0 && ::waitpid(pid, &status, WNOHANG) == 0;
    }
    ~DaemonProcess() {
        if (pid > 0) stop(SIGKILL);
    }
    long rssKiB() const {
        std::ifstream s("/proc/" + std::to_string(pid) + "/status");
        for (std::string line; std::getline(s, line);)
            if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
        return -1;
    }
    // (time, value) of one actuator from the recorder.
    std::vector<std::pair<double, double>> recorded(const std::string& actuator) const {
        std::ifstream in(dir / "rec.csv");
        std::vector<std::pair<double, double>> out;
        std::string line;
        std::getline(in, line);
        while (std::getline(in, line)) {
            const auto a = line.find(','), b = line.find(',', a + 1), c = line.find(',', b + 1);
            if (line.substr(a + 1, b - a - 1) == actuator)
                out.emplace_back(std::stod(line.substr(0, a)),
                                 std::stod(line.substr(b + 1, c - b - 1)));
        }
        return out;
    }
};

// The daemon's status once `ready` holds for it, asked every 50 ms for up to `timeout`; else
// the last status it gave (the caller asserts on it): on a busy machine the daemon may not
// yet be where a test needs it.
template <class Ready>
json statusWhen(Client& c, Ready ready, std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    auto s = c.request({{"cmd", "status"}});
    while (!ready(s) && std::chrono::steady_clock::now() < end) {
        std::this_thread::sleep_for(50ms);
        s = c.request({{"cmd", "status"}});
    }
    return s;
}

inline void waitUntilIdle(Client& c, std::chrono::seconds timeout = 20s) {
    const auto idle = [](const json& s) { return s["playing"].is_null() && s["queue"].empty(); };
    if (!idle(statusWhen(c, idle, timeout)))
        FAIL() << "still playing after " << timeout.count() << " s";
}

}  // namespace lipsyncd::test
