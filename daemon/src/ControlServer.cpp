// The control socket: a Unix stream socket, one JSON request per line, one JSON reply per line,
// any number of clients, all non-blocking inside the daemon's poll() loop. A malformed line
// gets an error reply; a client that stops reading its subscription is dropped, not waited for.
#include "ControlServer.hpp"

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace lipsyncd::daemon {

namespace {
constexpr std::size_t kMaxLine = 64 * 1024;
constexpr std::size_t kMaxBacklog =
    1024 * 1024;  // bytes queued to a slow client before it is dropped
}  // namespace

ControlServer::ControlServer(const std::filesystem::path& path, unsigned mode) : path_(path) {
    sockaddr_un addr{};
    if (path.string().size() >= sizeof(addr.sun_path))
        throw InputError(path.string() + ": socket path too long");
    std::filesystem::create_directories(path.parent_path());
    fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd_ < 0) throw std::runtime_error(std::string("control socket: ") + std::strerror(errno));
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, path.c_str(), sizeof(addr.sun_path) - 1);
    ::unlink(path.c_str());  // a stale socket from a crashed run
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0 || ::listen(fd_, 16) < 0) {
        const std::string why = std::strerror(errno);
        ::close(fd_);
        throw InputError(path.string() + ": cannot listen (" + why + ")");
    }
    ::chmod(path.c_str(), mode);
}

ControlServer::~ControlServer() {
    for (auto& c : clients_) ::close(c.fd);
    if (fd_ >= 0) ::close(fd_);
    ::unlink(path_.c_str());
}

void ControlServer::addPollFds(std::vector<pollfd>& fds) const {
    fds.push_back({fd_, POLLIN, 0});
    for (const auto& c : clients_)
        fds.push_back({c.fd, static_cast<short>(POLLIN | (c.out.empty() ? 0 : POLLOUT)), 0});
}

void ControlServer::service(const Handler& handle) {
    for (;;) {
        const int fd = ::accept4(fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
        if (fd < 0) break;
        clients_.push_back({fd, {}, {}, false, false});
    }
    for (auto& c : clients_) {
        readFrom(c);
        for (auto nl = c.in.find('\n'); nl != std::string::npos && !c.closed;
             nl = c.in.find('\n')) {
            const std::string line = c.in.substr(0, nl);
            c.in.erase(0, nl + 1);
            if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
            c.out += reply(line, c, handle).dump() + "\n";
        }
        if (c.in.size() > kMaxLine) {
            c.out += nlohmann::json{{"ok", false}, {"error", "request longer than 64 KiB"}}.dump() +
                     "\n";
            c.in.clear();
        }
        flush(c);
    }
    std::erase_if(clients_, [](const Client& c) {
        if (c.closed) ::close(c.fd);
        return c.closed;
    });
}

nlohmann::json ControlServer::reply(const std::string& line, Client& client,
                                    const Handler& handle) {
    nlohmann::json request;
    try {
        request = nlohmann::json::parse(line);
    } catch (const nlohmann::json::parse_error& e) {
        return {{"ok", false}, {"error", std::string("not JSON: ") + e.what()}};
    }
    if (!request.is_object() || !request.contains("cmd") || !request["cmd"].is_string())
        return {{"ok", false},
                {"error",
                 "expected an object with \"cmd\" (play, say, stop, queue, status, live, reload, "
                 "subscribe)"}};
    if (request["cmd"] == "subscribe") {
        client.subscribed = request.value("on", true);
        return {{"ok", true}, {"subscribed", client.subscribed}};
    }
    return handle(request);
}

void ControlServer::readFrom(Client& c) {
    char buf[4096];
    for (;;) {
        const auto n = ::read(c.fd, buf, sizeof buf);
        if (n > 0) {
            c.in.append(buf, static_cast<std::size_t>(n));
        } else if (n == 0) {
            c.eof = true;  // answer what came, then close
            return;
        } else {
            if (errno != EAGAIN && errno != EWOULDBLOCK) c.closed = true;
            return;
        }
    }
}

void ControlServer::flush(Client& c) {
    while (!c.out.empty()) {
        const auto n = ::send(c.fd, c.out.data(), c.out.size(), MSG_NOSIGNAL);
        if (n <= 0) {
            if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) c.closed = true;
            break;
        }
        c.out.erase(0, static_cast<std::size_t>(n));
    }
    if (c.eof && c.out.empty()) c.closed = true;
    if (c.out.size() > kMaxBacklog) c.closed = true;
}

void ControlServer::broadcast(const nlohmann::json& event) {
    const auto text = event.dump() + "\n";
    for (auto& c : clients_)
        if (c.subscribed && !c.closed) {
            c.out += text;
            flush(c);
        }
}

std::size_t ControlServer::clients() const {
    return clients_.size();
}

}  // namespace lipsyncd::daemon
