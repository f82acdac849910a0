// The control socket (internal to the daemon).
#pragma once

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>

#include <chrono>
#include <functional>
#include <lipsyncd/daemon.hpp>
#include <nlohmann/json.hpp>

namespace lipsyncd::daemon {

class ControlServer {
  public:
    using Handler = std::function<nlohmann::json(const nlohmann::json&)>;
    using Log = std::function<void(const std::string&)>;
    // InputError when the path is not ours to take: another daemon answers there, or it is
    // not a socket.
    ControlServer(const std::filesystem::path& path, unsigned mode, std::size_t maxClients,
                  Log log);
    ~ControlServer();
    ControlServer(const ControlServer&) = delete;
    ControlServer& operator=(const ControlServer&) = delete;

    void addPollFds(std::vector<pollfd>& fds) const;
    void service(const Handler& handle);          // accept, read, answer, write: never blocks
    void broadcast(const nlohmann::json& event);  // to subscribers
    // A line already serialised (the tick's frame events): copied into each subscriber's
    // outgoing buffer, whose capacity stays once it has grown (no allocation per event).
    void broadcast(std::string_view line);
    std::size_t clients() const;
    std::size_t subscribers() const;
    // One request line's reply (subscribe sets `subscribed`); never throws.
    static nlohmann::json reply(const std::string& line, bool& subscribed, const Handler& handle);
    static std::string serialise(const nlohmann::json& reply);  // one line, always valid JSON
    void setMaxClients(std::size_t n);
    const std::filesystem::path& path() const { return path_; }

  private:
    struct Client {
        int fd;
        std::string in, out;
        bool subscribed, closed;
        bool eof = false;
        bool discarding = false;  // inside a line that was too long: dropped up to its newline
    };
    using LineHandler = std::function<void(const std::string&)>;

    void readFrom(Client& c, const LineHandler& onLine);
    void take(Client& c, std::string_view bytes, const LineHandler& onLine);
    void flush(Client& c);

    void claim(const std::filesystem::path& path);
    const sockaddr* address() const;
    void acceptClients();
    void refuseForLackOfFds();
    static void turnAway(int fd, const std::string& why);

    std::filesystem::path path_;
    sockaddr_un addr_{};
    ino_t inode_ = 0;  // of the socket this server made
    std::size_t maxClients_;
    Log log_;
    int fd_ = -1;
    int spare_ = -1;  // a descriptor held back for refusing a client when none are left
    std::chrono::steady_clock::time_point acceptPausedUntil_{};
    std::vector<Client> clients_;
};

}  // namespace lipsyncd::daemon
