// A Pololu Maestro servo controller on a serial port (Pololu Maestro Servo Controller User's
// Guide, 5.e "Serial Servo Commands"). Set Target is 0x84, channel, then the target in
// quarter-µs as two 7-bit bytes; in the Pololu protocol (for several boards on one TTL line)
// the same command is 0xAA, device number, 0x04, channel, low, high. Target 0 stops a
// channel's pulses (a relaxed servo). The port is raw and non-blocking: a full output queue
// drops a frame (the next one carries the targets again), never stalls the caller.
#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <lipsyncd/output.hpp>
#include <stdexcept>

#include "DeviceFiles.hpp"

namespace lipsyncd::output {

namespace {
constexpr std::uint8_t kSetTarget = 0x84, kSetSpeed = 0x87, kSetAcceleration = 0x89;
constexpr unsigned kNone = ~0u;
constexpr int kWriteWaitMs = 2;  // how long a partly written frame may wait for the rest

speed_t baudConstant(unsigned baud) {
    switch (baud) {
        case 9600:
            return B9600;
        case 19200:
            return B19200;
        case 38400:
            return B38400;
        case 57600:
            return B57600;
        case 230400:
            return B230400;
        default:
            return B115200;
    }
}

std::string openError(const std::string& port, int error) {
    if (error == ENOENT || error == ENXIO || error == ENODEV)
        return "no such port (is the board plugged in? `lipsync devices` lists the serial ports)";
    if (error == EACCES || error == EPERM)
        return "permission denied (add the user to group dialout)";
    return port + ": " + std::strerror(error);
}

bool gone(int error) {
    return error == EIO || error == ENXIO || error == ENODEV || error == EBADF;
}
}  // namespace

std::size_t MaestroSink::encode(std::span<std::uint8_t, 6> out, int device, std::uint8_t command,
                                unsigned channel, unsigned value) {
    std::size_t n = 0;
    if (device >= 0) {
        out[n++] = 0xaa;
        out[n++] = static_cast<std::uint8_t>(device);
        out[n++] = command & 0x7f;  // the Pololu protocol drops the command's top bit
    } else {
        out[n++] = command;
    }
    out[n++] = static_cast<std::uint8_t>(channel);
    out[n++] = static_cast<std::uint8_t>(value & 0x7f);
    out[n++] = static_cast<std::uint8_t>((value >> 7) & 0x7f);
    return n;
}

unsigned MaestroSink::speed(const ActuatorConfig& a) {
    // The steepest µs per unit of value (a linkage makes it vary), times the slew: the most
    // µs per second the commands ever ask for. Rounded down, so the board never moves faster.
    constexpr int kSamples = 64;
    double steepest = 0;
    for (int i = 0; i < kSamples; ++i) {
        const double v0 = a.min + (a.max - a.min) * i / kSamples;
        const double v1 = a.min + (a.max - a.min) * (i + 1) / kSamples;
        steepest =
            std::max(steepest, std::abs(servoPulseUs(a, v1) - servoPulseUs(a, v0)) / (v1 - v0));
    }
    const double quarterUsPer10ms = steepest * a.slew * 4 / 100;
    return static_cast<unsigned>(std::clamp(std::floor(quarterUsPer10ms), 1.0, 16383.0));
}

unsigned MaestroSink::acceleration(const ActuatorConfig& a) {
    if (a.rampSeconds <= 0) return 0;
    // Speed units gained per 80 ms, so the slew speed is reached within the ramp.
    const double perStep = speed(a) * 0.08 / a.rampSeconds;
    return static_cast<unsigned>(std::clamp(std::ceil(perStep), 1.0, 255.0));
}

MaestroSink::MaestroSink(const Puppet& puppet, const std::string& port, Log log)
    : ServoBoardSink(
          puppet,
          [port](const ActuatorConfig& a) {
              return a.backend == Backend::Maestro && a.port == port;
          },
          "Maestro on " + port, std::move(log)),
      port_(port),
      sent_(channels_.size(), kNone),
      frame_(channels_.size() * 12) {}

MaestroSink::~MaestroSink() {
    close();
}

void MaestroSink::open() {
    fd_ = ::open(port_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) throw std::runtime_error(openError(port_, errno));
    termios tio{};
    if (tcgetattr(fd_, &tio) != 0)
        throw std::runtime_error(errno == ENOTTY ? "not a serial port (a tty)"
                                                 : std::string(std::strerror(errno)));
    // Raw bytes: no newline translation, no echo, no signals (a 0x0A inside a target must
    // arrive as 0x0A).
    cfmakeraw(&tio);
    tio.c_cflag |= CLOCAL | CREAD;
    const speed_t baud = baudConstant(channels_.empty() ? 115200 : channels_.front().config->baud);
    cfsetispeed(&tio, baud);
    cfsetospeed(&tio, baud);
    if (tcsetattr(fd_, TCSANOW, &tio) != 0)
        throw std::runtime_error(std::string("cannot configure the port: ") + std::strerror(errno));
    // The board's own limits, from the puppet: a second safety layer behind the slew limit.
    std::size_t n = 0;
    for (const auto& [index, config] : channels_) {
        auto out = std::span(frame_).subspan(n).first<6>();
        n += encode(out, config->maestroDevice, kSetSpeed, config->channel, speed(*config));
        out = std::span(frame_).subspan(n).first<6>();
        n += encode(out, config->maestroDevice, kSetAcceleration, config->channel,
                    acceleration(*config));
    }
    if (!writeAll(std::span(frame_).first(n))) throw std::runtime_error("write failed");
    std::fill(sent_.begin(), sent_.end(), kNone);
}

bool MaestroSink::writeAll(std::span<const std::uint8_t> bytes) {
    while (!bytes.empty()) {
        const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
        if (n > 0) {
            bytes = bytes.subspan(static_cast<std::size_t>(n));
            continue;
        }
        if (n < 0 && gone(errno)) return false;
        if (n < 0 && errno != EAGAIN && errno != EINTR) return false;
        pollfd p{fd_, POLLOUT, 0};
        if (poll(&p, 1, kWriteWaitMs) <= 0) {
            ++dropped_;  // the port has no room: this frame is lost, the next resends
            return true;
        }
        if (p.revents & (POLLHUP | POLLERR)) return false;
    }
    return true;
}

bool MaestroSink::send(std::span<const ActuatorCommand> commands) {
    std::size_t n = 0;
    for (std::size_t k = 0; k < channels_.size(); ++k) {
        const auto& [index, config] = channels_[k];
        const auto& c = commands[index];
        const unsigned target =
            c.active ? static_cast<unsigned>(std::lround(4 * servoPulseUs(*config, c.value))) : 0;
        if (target == sent_[k]) continue;
        n += encode(std::span(frame_).subspan(n).first<6>(), config->maestroDevice, kSetTarget,
                    config->channel, target);
    }
    if (n == 0) return true;
    const std::size_t droppedBefore = dropped_;
    if (!writeAll(std::span(frame_).first(n))) return false;
    if (dropped_ != droppedBefore) return true;  // not sent: keep the old targets to compare
    for (std::size_t k = 0; k < channels_.size(); ++k) {
        const auto& c = commands[channels_[k].actuator];
        sent_[k] = c.active ? static_cast<unsigned>(
                                  std::lround(4 * servoPulseUs(*channels_[k].config, c.value)))
                            : 0;
    }
    return true;
}

void MaestroSink::close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
}

std::vector<std::string> listSerialPorts(const std::filesystem::path& dev) {
    std::vector<std::string> out;
    std::error_code ec;
    for (const auto& link : sortedEntries(dev / "serial" / "by-id")) {
        const auto name = link.filename().string();
        std::string note;
        // A Maestro shows two ports: interface 00 takes commands, 02 is its TTL serial line.
        if (name.find("Maestro") != std::string::npos)
            note = name.ends_with("-if00") ? "  <- Maestro command port: use this one"
                                           : "  (Maestro TTL port)";
        const auto target = std::filesystem::canonical(link, ec);
        out.push_back(link.string() + " -> " + (ec ? "?" : target.string()) + note);
    }
    for (const auto& t : sortedEntries(dev, {"ttyACM", "ttyUSB"})) out.push_back(t.string());
    return out;
}

}  // namespace lipsyncd::output
