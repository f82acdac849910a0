// Fakes behind the hardware seams, and small puppets written in tests.
#pragma once

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <lipsyncd/output.hpp>
#include <mutex>

namespace lipsyncd::test {

inline std::filesystem::path writePuppet(const std::string& name, const std::string& toml) {
    const auto path = std::filesystem::temp_directory_path() /
                      ("lipsyncd_" + std::to_string(::getpid()) + "_" + name + ".toml");
    std::ofstream(path) << toml;
    return path;
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

}  // namespace lipsyncd::test
