#include "MemoryWav.hpp"

#include <sndfile.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <lipsyncd/core.hpp>

namespace lipsyncd::daemon {

MemoryWav::MemoryWav(std::span<const float> samples, int rate) {
    fd_ = ::memfd_create("lipsyncd-live-line", MFD_CLOEXEC);
    if (fd_ < 0) throw InputError(std::string("memfd_create: ") + std::strerror(errno));
    path_ = "/proc/self/fd/" + std::to_string(fd_);
    SF_INFO info{};
    info.samplerate = rate;
    info.channels = 1;
    info.format = SF_FORMAT_WAV | SF_FORMAT_FLOAT;
    SNDFILE* f = sf_open_fd(fd_, SFM_WRITE, &info, SF_FALSE);  // the fd stays ours
    const bool written =
        f && sf_writef_float(f, samples.data(), static_cast<sf_count_t>(samples.size())) ==
                 static_cast<sf_count_t>(samples.size());
    const std::string why = sf_strerror(f);
    if (f) sf_close(f);
    if (!written) {
        ::close(fd_);
        throw InputError("writing a live line to memory: " + why);
    }
}

MemoryWav::~MemoryWav() {
    ::close(fd_);
}

std::string MemoryWav::named(std::string message, const std::string& what) const {
    const auto p = path_.string();
    for (auto at = message.find(p); at != std::string::npos; at = message.find(p, at + what.size()))
        message.replace(at, p.size(), what);
    return message;
}

}  // namespace lipsyncd::daemon
