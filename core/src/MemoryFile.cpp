#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <lipsyncd/core.hpp>
#include <utility>

namespace lipsyncd {

MemoryFile::MemoryFile(const char* name)
    : fd_(::memfd_create(name, MFD_CLOEXEC | MFD_ALLOW_SEALING)) {
    if (fd_ < 0) throw std::runtime_error(std::string("memfd_create: ") + std::strerror(errno));
    path_ = "/proc/self/fd/" + std::to_string(fd_);
}

MemoryFile::MemoryFile(MemoryFile&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), path_(std::move(other.path_)) {}

MemoryFile& MemoryFile::operator=(MemoryFile&& other) noexcept {
    if (this != &other) {
        if (fd_ >= 0) ::close(fd_);
        fd_ = std::exchange(other.fd_, -1);
        path_ = std::move(other.path_);
    }
    return *this;
}

MemoryFile::~MemoryFile() {
    if (fd_ >= 0) ::close(fd_);
}

void MemoryFile::write(std::string_view bytes, const std::string& what) {
    for (std::size_t done = 0; done < bytes.size();) {
        const auto n = ::write(fd_, bytes.data() + done, bytes.size() - done);
        if (n <= 0)
            throw std::runtime_error("writing " + what + " to memory: " + std::strerror(errno));
        done += static_cast<std::size_t>(n);
    }
}

void MemoryFile::seal() {
    ::fcntl(fd_, F_ADD_SEALS, F_SEAL_WRITE | F_SEAL_GROW | F_SEAL_SHRINK | F_SEAL_SEAL);
}

std::string MemoryFile::named(std::string message, const std::string& what) const {
    const auto p = path_.string();
    for (auto at = message.find(p); at != std::string::npos; at = message.find(p, at + what.size()))
        message.replace(at, p.size(), what);
    return message;
}

}  // namespace lipsyncd
