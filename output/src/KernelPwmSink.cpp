// Kernel PWM through sysfs (Documentation/driver-api/pwm.rst, "Using PWMs with the sysfs
// interface"): a channel is exported, given its period, duty cycle and enable, all in ns. The
// SoC's PWM block times the pulses, so they do not jitter. Only the duty cycle changes while
// the mouth moves: one small write to a file kept open.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <lipsyncd/output.hpp>
#include <stdexcept>
#include <thread>

#include "DeviceFiles.hpp"

namespace lipsyncd::output {

namespace {
// After an export the kernel makes pwmN/ at once, but udev may take a moment to hand its
// files to group gpio: wait this long for them to become writable.
constexpr auto kExportWait = std::chrono::milliseconds(1000);
constexpr auto kExportPoll = std::chrono::milliseconds(10);

// One value written in one write(), as sysfs wants it; false with errno set on failure.
bool writeValue(int fd, std::int64_t value) {
    char buf[24];
    const int n = std::snprintf(buf, sizeof buf, "%lld\n", static_cast<long long>(value));
    return ::pwrite(fd, buf, static_cast<std::size_t>(n), 0) == n;
}

void writeFile(const std::filesystem::path& file, std::int64_t value) {
    const int fd = ::open(file.c_str(), O_WRONLY | O_CLOEXEC);
    const bool ok = fd >= 0 && writeValue(fd, value);
    const int error = errno;
    if (fd >= 0) ::close(fd);
    if (!ok)
        throw std::runtime_error(file.string() + ": " + std::strerror(error) +
                                 (error == EACCES ? " (add the user to group gpio)" : ""));
}

int openWhenWritable(const std::filesystem::path& file) {
    const auto deadline = std::chrono::steady_clock::now() + kExportWait;
    for (;;) {
        const int fd = ::open(file.c_str(), O_WRONLY | O_CLOEXEC);
        if (fd >= 0) return fd;
        if ((errno != ENOENT && errno != EACCES) || std::chrono::steady_clock::now() > deadline)
            throw std::runtime_error(file.string() + ": " + std::strerror(errno) +
                                     (errno == EACCES ? " (add the user to group gpio)" : ""));
        std::this_thread::sleep_for(kExportPoll);
    }
}

long channelCount(const std::filesystem::path& chip) {
    long n = -1;
    std::ifstream(chip / "npwm") >> n;
    return n;
}
}  // namespace

KernelPwmSink::KernelPwmSink(const Puppet& puppet, unsigned chip, std::filesystem::path root,
                             Log log)
    : ServoBoardSink(
          puppet,
          [chip](const ActuatorConfig& a) {
              return a.backend == Backend::Pwm && a.pwmChip == chip;
          },
          "PWM chip " + (root / ("pwmchip" + std::to_string(chip))).string(), std::move(log)),
      chipDir_(root / ("pwmchip" + std::to_string(chip))),
      dutyFd_(channels_.size(), -1),
      sent_(channels_.size(), -1),
      exported_(channels_.size(), false) {}

KernelPwmSink::~KernelPwmSink() {
    // After the rest pose: pulses off, and the channels handed back as we found them.
    for (std::size_t k = 0; k < channels_.size(); ++k) {
        if (dutyFd_[k] < 0) continue;
        const auto dir = chipDir_ / ("pwm" + std::to_string(channels_[k].config->channel));
        try {
            writeFile(dir / "enable", 0);
            if (exported_[k]) writeFile(chipDir_ / "unexport", channels_[k].config->channel);
        } catch (const std::runtime_error&) {
            // (nothing more to do on the way out)
        }
    }
    close();
}

void KernelPwmSink::open() {
    if (!std::filesystem::is_directory(chipDir_))
        throw std::runtime_error(
            "no such PWM chip (enable the PWM, e.g. dtoverlay=pwm-2chan on a Raspberry Pi; "
            "`lipsync devices` lists the chips)");
    const long count = channelCount(chipDir_);
    for (std::size_t k = 0; k < channels_.size(); ++k) {
        const auto& a = *channels_[k].config;
        if (count >= 0 && a.channel >= count)
            throw std::runtime_error("channel " + std::to_string(a.channel) + ": the chip has " +
                                     std::to_string(count) + " channels");
        const auto dir = chipDir_ / ("pwm" + std::to_string(a.channel));
        if (!std::filesystem::exists(dir)) {
            writeFile(chipDir_ / "export", a.channel);
            exported_[k] = true;
        }
        dutyFd_[k] = openWhenWritable(dir / "duty_cycle");
        // A new period is refused while the old duty cycle is longer: duty 0 first.
        if (!writeValue(dutyFd_[k], 0))
            throw std::runtime_error((dir / "duty_cycle").string() + ": " + std::strerror(errno));
        writeFile(dir / "period", std::llround(1e9 / a.frequencyHz));
        writeFile(dir / "enable", 1);
        sent_[k] = 0;
    }
}

bool KernelPwmSink::send(std::span<const ActuatorCommand> commands) {
    for (std::size_t k = 0; k < channels_.size(); ++k) {
        const auto& [index, config] = channels_[k];
        const auto& c = commands[index];
        // Duty 0 is no pulse at all: a relaxed servo.
        const std::int64_t duty =
            c.active ? std::llround(servoPulseUs(*config, c.value) * 1000) : 0;
        if (duty == sent_[k]) continue;
        if (!writeValue(dutyFd_[k], duty)) return false;
        sent_[k] = duty;
    }
    return true;
}

void KernelPwmSink::close() {
    for (auto& fd : dutyFd_) {
        if (fd >= 0) ::close(fd);
        fd = -1;
    }
}

std::vector<std::string> listPwmChips(const std::filesystem::path& root) {
    std::vector<std::string> out;
    for (const auto& chip : sortedEntries(root, {"pwmchip"})) {
        const auto name = chip.filename().string();
        out.push_back(name + ": " + std::to_string(channelCount(chip)) +
                      " channels (chip = " + name.substr(7) + ")");
    }
    return out;
}

}  // namespace lipsyncd::output
