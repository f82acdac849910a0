// Fakes behind the hardware seams, and small puppets written in tests.
#pragma once

#include <unistd.h>

#include <array>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <lipsyncd/output.hpp>
#include <mutex>
#include <string>

namespace lipsyncd::test {

inline std::filesystem::path writePuppet(const std::string& name, const std::string& toml) {
    const auto path = std::filesystem::temp_directory_path() /
                      ("lipsyncd_" + std::to_string(::getpid()) + "_" + name + ".toml");
    std::ofstream(path) << toml;
    return path;
}

// An actuator on no hardware: the output that must keep going when a board fails.
inline const std::string kVirtualActuator = R"([[actuator]]
name = "virtual"
backend = "virtual"
gains = { open = 1.0 }
min = 0.0
max = 1.0
)";

// For "permission denied" tests, whoever runs them: root gives up its rights (to nobody) in
// the death-test child; anyone else is refused a file with no permissions anyway.
inline void dropPrivileges() {
    if (::getuid() != 0) return;
    if (::setgid(65534) != 0 || ::setuid(65534) != 0) std::_Exit(2);
}

// Records every edge with the fake clock's time.
class FakeGpioLine : public output::GpioLine {
  public:
    explicit FakeGpioLine(const std::int64_t* clock) : clock_(clock) {}
    void set(bool high) override {
        std::lock_guard lock(mutex_);
        edges.emplace_back(clock_ ? *clock_ : 0, high);
    }
    std::vector<std::pair<std::int64_t, bool>> edges;
    std::mutex mutex_;

  private:
    const std::int64_t* clock_;
};

// A HID board that can be unplugged and plugged back.
struct FakeHidBoard {
    bool present = true;
    std::vector<std::vector<std::uint8_t>> reports;
};

class FakeHidDevice : public output::HidDevice {
  public:
    explicit FakeHidDevice(FakeHidBoard& board) : board_(&board) {}
    bool write(std::span<const std::uint8_t> report) override {
        if (!board_->present) return false;
        board_->reports.emplace_back(report.begin(), report.end());
        return true;
    }

  private:
    FakeHidBoard* board_;
};

// A PCA9685 at register level (NXP PCA9685 datasheet, 7.3): MODE1 with RESTART, AI and
// SLEEP; PRE_SCALE that keeps a write only while the oscillator sleeps; LEDn_ON/OFF and the
// ALL_LED registers; register auto-increment only when AI is set. It answers only when
// `present`.
struct FakePca9685 {
    static constexpr std::uint8_t kMode1 = 0x00, kPreScale = 0xfe, kSleep = 0x10, kRestart = 0x80,
                                  kAutoIncrement = 0x20;
    std::array<std::uint8_t, 256> reg{};
    bool present = true;
    std::vector<std::uint8_t> mode1Writes;  // every value written to MODE1, in order
    int prescaleWritesLost = 0;             // PRE_SCALE written while awake (ignored)
    std::size_t writes = 0;                 // bus transactions that wrote

    FakePca9685() {
        reg[kMode1] = 0x11;  // power-on: asleep, all-call
        reg[0x01] = 0x04;
        reg[kPreScale] = 0x1e;
        for (int ch = 0; ch < 16; ++ch) reg[9 + 4 * ch] = 0x10;  // full-off
    }
    bool sleeping() const { return reg[kMode1] & kSleep; }
    bool fullOff(int ch) const { return reg[9 + 4 * ch] & 0x10; }
    int off(int ch) const { return reg[8 + 4 * ch] | ((reg[9 + 4 * ch] & 0x0f) << 8); }
    bool anyRunning() const {
        for (int ch = 0; ch < 16; ++ch)
            if (!fullOff(ch)) return true;
        return false;
    }
    void set(std::uint8_t r, std::uint8_t v) {
        if (r == kPreScale && !sleeping()) {
            ++prescaleWritesLost;
            return;
        }
        if (r == kMode1) {
            mode1Writes.push_back(v);
            // RESTART reads 1 after going to sleep with channels running; writing 1 clears it.
            bool restart = (reg[kMode1] & kRestart) && !(v & kRestart);
            if ((v & kSleep) && !sleeping() && anyRunning()) restart = true;
            reg[kMode1] = static_cast<std::uint8_t>((v & ~kRestart) | (restart ? kRestart : 0));
            return;
        }
        if (r >= 0xfa && r <= 0xfd) {  // ALL_LED_ON_L .. ALL_LED_OFF_H: every channel
            for (int ch = 0; ch < 16; ++ch) reg[6 + 4 * ch + (r - 0xfa)] = v;
            return;
        }
        reg[r] = v;
    }
    bool write(std::span<const std::uint8_t> bytes) {
        if (!present || bytes.empty()) return false;
        ++writes;
        std::uint8_t r = bytes[0];
        for (std::size_t i = 1; i < bytes.size(); ++i) {
            set(r, bytes[i]);
            if (reg[kMode1] & kAutoIncrement) ++r;
        }
        return true;
    }
    bool read(std::uint8_t r, std::span<std::uint8_t> out) {
        if (!present) return false;
        for (auto& b : out) {
            b = (r >= 0xfa && r <= 0xfd) ? 0 : reg[r];  // ALL_LED reads as 0
            if (reg[kMode1] & kAutoIncrement) ++r;
        }
        return true;
    }
};

class FakeI2cDevice : public output::I2cDevice {
  public:
    explicit FakeI2cDevice(FakePca9685& chip) : chip_(&chip) {}
    bool write(std::span<const std::uint8_t> bytes) override { return chip_->write(bytes); }
    bool read(std::uint8_t reg, std::span<std::uint8_t> out) override {
        return chip_->read(reg, out);
    }

  private:
    FakePca9685* chip_;
};

}  // namespace lipsyncd::test
