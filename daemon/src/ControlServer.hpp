// The control socket (internal to the daemon).
#pragma once

#include <poll.h>

#include <lipsyncd/daemon.hpp>
#include <nlohmann/json.hpp>

namespace lipsyncd::daemon {

class ControlServer {
  public:
    using Handler = std::function<nlohmann::json(const nlohmann::json&)>;
    ControlServer(const std::filesystem::path& path, unsigned mode);
    ~ControlServer();
    ControlServer(const ControlServer&) = delete;
    ControlServer& operator=(const ControlServer&) = delete;

    void addPollFds(std::vector<pollfd>& fds) const;
    void service(const Handler& handle);          // accept, read, answer, write: never blocks
    void broadcast(const nlohmann::json& event);  // to subscribers
    std::size_t clients() const;
    const std::filesystem::path& path() const { return path_; }

  private:
    struct Client {
        int fd;
        std::string in, out;
        bool subscribed, closed;
        bool eof = false;
    };
    nlohmann::json reply(const std::string& line, Client& client, const Handler& handle);
    void readFrom(Client& c);
    void flush(Client& c);

    std::filesystem::path path_;
    int fd_ = -1;
    std::vector<Client> clients_;
};

}  // namespace lipsyncd::daemon
