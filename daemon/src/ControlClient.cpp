// The control socket's client: `lipsync ctl` and the tests. Every step waits in poll() with the
// deadline, so a daemon that is stuck (or a socket that is not a daemon's) gives an error.
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <lipsyncd/daemon.hpp>
#include <nlohmann/json.hpp>

namespace lipsyncd::daemon {

ControlClient::ControlClient(const std::filesystem::path& socket, std::chrono::milliseconds timeout)
    : timeout_(timeout), socket_(socket) {
    sockaddr_un addr{};
    if (socket.string().size() >= sizeof(addr.sun_path))
        throw InputError(socket.string() + ": socket path too long");
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, socket.c_str(), sizeof(addr.sun_path) - 1);
    fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd_ < 0) throw std::runtime_error(std::string("socket: ") + std::strerror(errno));
    // A Unix socket's connect fails with EAGAIN while the daemon's backlog is full: retry
    // until the deadline.
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) {
        if (errno == EAGAIN && std::chrono::steady_clock::now() < deadline) {
            ::usleep(10'000);
            continue;
        }
        const std::string why = std::strerror(errno);
        ::close(fd_);
        throw InputError(socket.string() + ": cannot connect to lipsyncd (" + why +
                         "); is it running? (--socket)");
    }
}

ControlClient::~ControlClient() {
    if (fd_ >= 0) ::close(fd_);
}

void ControlClient::waitFor(short events, const char* what) const {
    pollfd p{fd_, events, 0};
    const int n = ::poll(&p, 1, static_cast<int>(timeout_.count()));
    if (n == 0)
        throw std::runtime_error(socket_.string() + ": lipsyncd did not answer (" + what +
                                 ") within " + std::to_string(timeout_.count()) + " ms");
    if (n < 0) throw std::runtime_error(socket_.string() + ": " + std::strerror(errno));
}

void ControlClient::sendRaw(std::string_view bytes) {
    while (!bytes.empty()) {
        const auto n = ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL);
        if (n > 0) {
            bytes.remove_prefix(static_cast<std::size_t>(n));
        } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            waitFor(POLLOUT, "write");
        } else {
            throw std::runtime_error(socket_.string() + ": write failed (" + std::strerror(errno) +
                                     ")");
        }
    }
}

std::string ControlClient::readLine() {
    for (;;) {
        if (const auto nl = buffer_.find('\n'); nl != std::string::npos) {
            auto line = buffer_.substr(0, nl);
            buffer_.erase(0, nl + 1);
            return line;
        }
        char buf[4096];
        const auto n = ::read(fd_, buf, sizeof buf);
        if (n > 0) {
            buffer_.append(buf, static_cast<std::size_t>(n));
        } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            waitFor(POLLIN, "read");
        } else {
            throw std::runtime_error(socket_.string() + ": lipsyncd closed the connection");
        }
    }
}

nlohmann::json ControlClient::request(const nlohmann::json& r) {
    sendRaw(r.dump() + "\n");
    const auto line = readLine();
    auto reply = nlohmann::json::parse(line, nullptr, false);
    if (reply.is_discarded())
        throw std::runtime_error(socket_.string() + ": not a JSON reply: " + line.substr(0, 200));
    return reply;
}

}  // namespace lipsyncd::daemon
