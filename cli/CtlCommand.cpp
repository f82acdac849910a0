// lipsync ctl: the client of lipsyncd's control socket (JSON lines).
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <iostream>
#include <lipsyncd/core.hpp>
#include <nlohmann/json.hpp>
#include <thread>

#include "Commands.hpp"

namespace lipsyncd::cli {

namespace {
// One connection; requests and replies are lines.
class ControlConnection {
  public:
    explicit ControlConnection(const std::string& path) {
        fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
        sockaddr_un addr{};
        addr.sun_family = AF_UNIX;
        std::strncpy(addr.sun_path, path.c_str(), sizeof(addr.sun_path) - 1);
        if (fd_ < 0 || ::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) {
            const std::string why = std::strerror(errno);
            if (fd_ >= 0) ::close(fd_);
            throw InputError(path + ": cannot connect to lipsyncd (" + why +
                             "); is it running? (--socket)");
        }
    }
    ~ControlConnection() { ::close(fd_); }
    ControlConnection(const ControlConnection&) = delete;
    ControlConnection& operator=(const ControlConnection&) = delete;

    void send(const nlohmann::json& request) {
        const auto line = request.dump() + "\n";
        if (::send(fd_, line.data(), line.size(), MSG_NOSIGNAL) !=
            static_cast<ssize_t>(line.size()))
            throw std::runtime_error("control socket: write failed");
    }
    std::string readLine() {
        for (;;) {
            const auto nl = buffer_.find('\n');
            if (nl != std::string::npos) {
                auto line = buffer_.substr(0, nl);
                buffer_.erase(0, nl + 1);
                return line;
            }
            char buf[4096];
            const auto n = ::read(fd_, buf, sizeof buf);
            if (n <= 0) throw std::runtime_error("control socket: lipsyncd closed the connection");
            buffer_.append(buf, static_cast<std::size_t>(n));
        }
    }

  private:
    int fd_ = -1;
    std::string buffer_;
};

struct CtlOptions {
    std::string socket = "/run/lipsyncd/control.sock";
    std::vector<std::string> args;
    int channel = -1;
    std::string voice;
    bool wait = false;
};

nlohmann::json requestFrom(const CtlOptions& o) {
    const auto& a = o.args;
    const std::string cmd = a.front();
    auto need = [&](std::size_t n, const char* usage) {
        if (a.size() != n)
            throw CLI::ValidationError("ctl", std::string("usage: lipsync ctl ") + usage);
    };
    if (cmd == "play") {
        need(2, "play FILE");
        nlohmann::json r = {{"cmd", "play"}, {"file", std::filesystem::absolute(a[1]).string()}};
        if (o.channel >= 0) r["channel"] = o.channel;
        return r;
    }
    if (cmd == "say") {
        if (a.size() < 2) throw CLI::ValidationError("ctl", "usage: lipsync ctl say TEXT...");
        std::string text;
        for (std::size_t i = 1; i < a.size(); ++i) text += (i > 1 ? " " : "") + a[i];
        nlohmann::json r = {{"cmd", "say"}, {"text", text}};
        if (!o.voice.empty()) r["voice"] = o.voice;
        return r;
    }
    if (cmd == "live") {
        need(2, "live on|off");
        return {{"cmd", "live"}, {"on", a[1] == "on"}};
    }
    if (cmd == "stop" || cmd == "status" || cmd == "queue" || cmd == "reload" ||
        cmd == "subscribe") {
        need(1, cmd.c_str());
        return {{"cmd", cmd}};
    }
    if (cmd == "raw") {
        need(2, "raw '{\"cmd\": ...}'");
        return nlohmann::json::parse(a[1]);
    }
    throw CLI::ValidationError(
        "ctl", "unknown command '" + cmd +
                   "' (play, say, stop, queue, status, live, reload, subscribe, raw)");
}

void runCtl(const CtlOptions& o) {
    const auto request = requestFrom(o);
    ControlConnection c(o.socket);
    c.send(request);
    const auto reply = nlohmann::json::parse(c.readLine());
    std::cout << reply.dump() << std::endl;
    if (!reply.value("ok", false))
        throw std::runtime_error("lipsyncd: " +
                                 reply.value("error", std::string("request refused")));
    if (request["cmd"] == "subscribe")
        for (;;) std::cout << c.readLine() << std::endl;  // until interrupted or the daemon goes
    // --wait: until nothing plays or is queued.
    while (o.wait) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        c.send({{"cmd", "status"}});
        const auto s = nlohmann::json::parse(c.readLine());
        if (s["playing"].is_null() && s["queue"].empty()) break;
    }
}
}  // namespace

void addCtlCommand(CLI::App& app) {
    auto o = std::make_shared<CtlOptions>();
    auto* cmd =
        app.add_subcommand("ctl",
                           "Talk to a running lipsyncd: play FILE, say TEXT, stop, queue, status, "
                           "live on|off, reload, subscribe, raw JSON");
    cmd->add_option("--socket", o->socket, "lipsyncd's control socket")->capture_default_str();
    cmd->add_option("--channel", o->channel, "play: analyse only this channel of the file");
    cmd->add_option("--voice", o->voice, "say: espeak-ng voice");
    cmd->add_flag("--wait", o->wait, "Return when nothing plays or is queued any more");
    cmd->add_option("request", o->args, "The request and its arguments")->required();
    cmd->callback([o] { runCtl(*o); });
}

}  // namespace lipsyncd::cli
