#include "MemoryWav.hpp"

#include <sndfile.h>

namespace lipsyncd::daemon {

MemoryWav::MemoryWav(std::span<const float> samples, int rate) {
    SF_INFO info{};
    info.samplerate = rate;
    info.channels = 1;
    info.format = SF_FORMAT_WAV | SF_FORMAT_FLOAT;
    SNDFILE* f = sf_open_fd(file_.fd(), SFM_WRITE, &info, SF_FALSE);  // the fd stays the file's
    const bool written =
        f && sf_writef_float(f, samples.data(), static_cast<sf_count_t>(samples.size())) ==
                 static_cast<sf_count_t>(samples.size());
    const std::string why = sf_strerror(f);
    if (f) sf_close(f);
    if (!written) throw InputError("writing a live line to memory: " + why);
}

}  // namespace lipsyncd::daemon
