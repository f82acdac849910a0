// The control socket: a Unix stream socket, one JSON request per line, one JSON reply per line,
// up to max_clients at once, all non-blocking inside the daemon's poll() loop. A malformed line
// gets an error reply on its own connection; a client that stops reading its subscription is
// dropped, not waited for.
#include "ControlServer.hpp"

#include <fcntl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <string_view>

namespace lipsyncd::daemon {

namespace {
constexpr std::size_t kMaxLine = 64 * 1024;
// Bytes queued to a slow client before it is dropped.
constexpr std::size_t kMaxBacklog = 1024 * 1024;
constexpr int kChunksPerPass = 16;
constexpr int kBacklog = 64;
constexpr auto kAcceptPause = std::chrono::milliseconds(100);

}  // namespace

// Replies are always valid JSON: text that is not UTF-8 (a request's bad byte quoted in an
// error, a name from a file) is replaced, never thrown on.
std::string ControlServer::serialise(const nlohmann::json& j) {
    return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

// An existing path is left alone unless it is a socket nobody answers on (a crashed run's):
// a live daemon's socket is refused, anything else (a file, a folder) is never removed.
void ControlServer::claim(const std::filesystem::path& path) {
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0) return;
    if (!S_ISSOCK(st.st_mode))
        throw InputError(path.string() + ": exists and is not a socket; not replacing it");
    const int probe = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const bool answers = probe >= 0 && ::connect(probe, address(), sizeof addr_) == 0;
    if (probe >= 0) ::close(probe);
    if (answers) throw InputError(path.string() + ": another lipsyncd answers on this socket");
    ::unlink(path.c_str());  // stale
}

ControlServer::ControlServer(const std::filesystem::path& path, unsigned mode,
                             std::size_t maxClients, Log log)
    : path_(path), maxClients_(maxClients), log_(std::move(log)) {
    if (path.string().size() >= sizeof(addr_.sun_path))
        throw InputError(path.string() + ": socket path too long");
    addr_.sun_family = AF_UNIX;
    std::strncpy(addr_.sun_path, path.c_str(), sizeof(addr_.sun_path) - 1);
    std::filesystem::create_directories(path.parent_path());
    claim(path);
    fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd_ < 0) throw std::runtime_error(std::string("control socket: ") + std::strerror(errno));
    if (::bind(fd_, address(), sizeof addr_) < 0 || ::listen(fd_, kBacklog) < 0) {
        const std::string why = std::strerror(errno);
        ::close(fd_);
        throw InputError(path.string() + ": cannot listen (" + why + ")");
    }
    struct stat st {};
    ::stat(path.c_str(), &st);
    inode_ = st.st_ino;
    ::chmod(path.c_str(), mode);
    spare_ = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
}

ControlServer::~ControlServer() {
    for (auto& c : clients_) ::close(c.fd);
    if (fd_ >= 0) ::close(fd_);
    if (spare_ >= 0) ::close(spare_);
    // Only the socket this server made: another daemon's (or a file since put there) stays.
    struct stat st {};
    if (::lstat(path_.c_str(), &st) == 0 && S_ISSOCK(st.st_mode) && st.st_ino == inode_)
        ::unlink(path_.c_str());
}

const sockaddr* ControlServer::address() const {
    return reinterpret_cast<const sockaddr*>(&addr_);
}

void ControlServer::addPollFds(std::vector<pollfd>& fds) const {
    if (std::chrono::steady_clock::now() >= acceptPausedUntil_) fds.push_back({fd_, POLLIN, 0});
    for (const auto& c : clients_)
        fds.push_back({c.fd, static_cast<short>(POLLIN | (c.out.empty() ? 0 : POLLOUT)), 0});
}

void ControlServer::service(const Handler& handle) {
    acceptClients();
    for (auto& c : clients_) {
        readFrom(c, [&](const std::string& line) {
            if (line.find_first_not_of(" \t\r") == std::string::npos) return;
            c.out += serialise(reply(line, c.subscribed, handle));
        });
        flush(c);
    }
    std::erase_if(clients_, [](const Client& c) {
        if (c.closed) ::close(c.fd);
        return c.closed;
    });
}

void ControlServer::acceptClients() {
    if (std::chrono::steady_clock::now() < acceptPausedUntil_) return;
    for (;;) {
        const int fd = ::accept4(fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
        if (fd < 0) {
            if (errno == EMFILE || errno == ENFILE) refuseForLackOfFds();
            return;
        }
        if (clients_.size() >= maxClients_) {
            turnAway(fd, "too many clients (" + std::to_string(maxClients_) +
                             "; max_clients in the config): try again later");
            continue;
        }
        ucred peer{};
        socklen_t len = sizeof peer;
        if (::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &peer, &len) == 0 && log_)
            log_("control: client pid " + std::to_string(peer.pid) + " uid " +
                 std::to_string(peer.uid) + " gid " + std::to_string(peer.gid));
        clients_.push_back({fd, {}, {}, false, false});
    }
}

void ControlServer::turnAway(int fd, const std::string& why) {
    const auto line = serialise({{"ok", false}, {"error", why}});
    [[maybe_unused]] const auto n = ::send(fd, line.data(), line.size(), MSG_NOSIGNAL);
    ::close(fd);
}

// Out of file descriptors: the waiting connection would keep poll() waking for ever. The
// spare descriptor kept for this moment lets it be accepted, told why and closed; without
// one, accepting pauses a little (degrades, never spins).
void ControlServer::refuseForLackOfFds() {
    if (spare_ >= 0) {
        ::close(spare_);
        const int fd = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC);
        if (fd >= 0) turnAway(fd, "lipsyncd is out of file descriptors: try again later");
        spare_ = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
    }
    if (spare_ < 0) acceptPausedUntil_ = std::chrono::steady_clock::now() + kAcceptPause;
    if (log_) log_("control: out of file descriptors; a connection was refused");
}

void ControlServer::setMaxClients(std::size_t n) {
    maxClients_ = n;
}

nlohmann::json ControlServer::reply(const std::string& line, bool& subscribed,
                                    const Handler& handle) {
    nlohmann::json request;
    try {
        request = nlohmann::json::parse(line);
    } catch (const nlohmann::json::exception& e) {  // bad syntax, or a number like 1e600
        return {{"ok", false}, {"error", std::string("not JSON: ") + e.what()}};
    }
    if (const auto bad = checkControlRequest(request)) return {{"ok", false}, {"error", *bad}};
    if (request["cmd"] == "subscribe") {
        subscribed = request.value("on", true);
        return {{"ok", true}, {"subscribed", subscribed}};
    }
    // Whatever goes wrong with one request is that request's reply, never the daemon's exit.
    try {
        return handle(request);
    } catch (const std::exception& e) {
        return {{"ok", false}, {"error", e.what()}};
    }
}

// Lines are cut while reading: a line that grows past kMaxLine is answered with one error and
// dropped up to its newline, so nothing of it (its tail included) ever runs as a request.
void ControlServer::take(Client& c, std::string_view bytes, const LineHandler& onLine) {
    while (!bytes.empty() && !c.closed) {
        const auto nl = bytes.find('\n');
        const auto part = bytes.substr(0, nl);
        if (!c.discarding) {
            c.in.append(part.substr(0, kMaxLine + 1 - std::min(c.in.size(), kMaxLine + 1)));
            if (c.in.size() > kMaxLine) {
                c.out += serialise({{"ok", false}, {"error", "request longer than 64 KiB"}});
                c.in.clear();
                c.discarding = true;
            }
        }
        if (nl == std::string_view::npos) return;
        if (!c.discarding) onLine(c.in);
        c.in.clear();
        c.discarding = false;
        bytes.remove_prefix(nl + 1);
    }
}

void ControlServer::readFrom(Client& c, const LineHandler& onLine) {
    char buf[4096];
    // A bounded amount per client and pass, so one flooding client cannot starve the others.
    for (int chunk = 0; chunk < kChunksPerPass && !c.closed; ++chunk) {
        const auto n = ::read(c.fd, buf, sizeof buf);
        if (n > 0) {
            take(c, std::string_view(buf, static_cast<std::size_t>(n)), onLine);
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
    broadcast(std::string_view(serialise(event)));
}

void ControlServer::broadcast(std::string_view line) {
    for (auto& c : clients_)
        if (c.subscribed && !c.closed) {
            c.out += line;
            flush(c);
        }
}

std::size_t ControlServer::clients() const {
    return clients_.size();
}

std::size_t ControlServer::subscribers() const {
    return static_cast<std::size_t>(std::count_if(clients_.begin(), clients_.end(),
                                                  [](const Client& c) { return c.subscribed; }));
}

}  // namespace lipsyncd::daemon
