// A pseudo-terminal for tests of serial backends: the program under test opens slave() as its
// port, and the test reads what arrived on the master side.
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <stdlib.h>
#include <unistd.h>

#include <cstdint>
#include <string>
#include <vector>

namespace lipsyncd::test {

class Pty {
  public:
    Pty() {
        master_ = posix_openpt(O_RDWR | O_NOCTTY);
        EXPECT_GE(master_, 0);
        EXPECT_EQ(grantpt(master_), 0);
        EXPECT_EQ(unlockpt(master_), 0);
        slave_ = ptsname(master_);
        fcntl(master_, F_SETFL, O_NONBLOCK);
    }
    ~Pty() { close(); }
    Pty(const Pty&) = delete;
    Pty& operator=(const Pty&) = delete;
    const std::string& slave() const { return slave_; }
    void close() {
        if (master_ >= 0) ::close(master_);
        master_ = -1;
    }
    // What has arrived so far; with quietMs, also what arrives until the line has been quiet
    // that long (a pty passes bytes on asynchronously, some after the write has returned, even
    // after the writer has exited: a single read once lost the tail of a stream in CI).
    std::vector<std::uint8_t> drain(int quietMs = 0) {
        std::vector<std::uint8_t> out;
        std::uint8_t buf[4096];
        for (pollfd p{master_, POLLIN, 0}; ::poll(&p, 1, quietMs) > 0;) {
            const ssize_t n = ::read(master_, buf, sizeof buf);
            if (n <= 0) break;
            out.insert(out.end(), buf, buf + n);
        }
        return out;
    }

  private:
    int master_ = -1;
    std::string slave_;
};

}  // namespace lipsyncd::test
