// Output benchmarks (issue 4): software servo PWM pulse jitter against a fake GPIO line that
// timestamps every edge with CLOCK_MONOTONIC (on a board, add the line write's own cost), and
// the cost of one actuator step for a puppet.
// Servo boards (issue 13): actuator commands per second and the write cost of one frame
// (every channel moving) for the PCA9685 (register-level fake: the CPU side; the I2C wire time
// is computed from the bytes), the Maestro (a real pseudo-terminal) and kernel PWM (a fake
// sysfs tree of plain files: the syscall side).
//
//   build/bench/output_bench
//   build/bench/output_bench --benchmark_filter='Frame'   # the servo boards only
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <lipsyncd/output.hpp>
#include <thread>

#include "OutputTestSupport.hpp"

namespace {

using namespace lipsyncd;

std::int64_t nowNs() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

using Edges = std::vector<std::pair<std::int64_t, bool>>;

class TimestampLine : public output::GpioLine {
  public:
    explicit TimestampLine(Edges& edges) : edges_(&edges) {}
    void set(bool high) override { edges_->emplace_back(nowNs(), high); }

  private:
    Edges* edges_;
};

// 100 periods (2 s) of one servo at 1500 µs on the real-time thread, as the daemon runs it.
void ServoPulseJitter(benchmark::State& state) {
    double widthMean = 0, widthMax = 0, startMax = 0;
    bool realtime = false;
    for (auto _ : state) {
        Edges recorded;
        recorded.reserve(1000);  // no allocation inside the pulse loop
        auto* edges = &recorded;
        auto line = std::make_unique<TimestampLine>(recorded);
        std::vector<output::ServoPwm::Servo> servos;
        servos.push_back({std::move(line), 1000, 2000, 0, 1});
        {
            output::ServoPwm pwm(std::move(servos), 50);
            pwm.set(0, 0.5, true);
            pwm.start();
            std::this_thread::sleep_for(std::chrono::milliseconds(2000));
            realtime = pwm.realtime();
        }
        std::vector<double> widthErr, startErr;
        std::int64_t firstRise = -1;
        int period = 0;
        for (std::size_t i = 0; i + 1 < edges->size(); ++i) {
            if (!(*edges)[i].second || (*edges)[i + 1].second) continue;
            const auto rise = (*edges)[i].first, fall = (*edges)[i + 1].first;
            if (firstRise < 0) firstRise = rise;
            widthErr.push_back(std::abs((fall - rise) / 1000.0 - 1500));
            startErr.push_back(std::abs((rise - firstRise) / 1000.0 - period * 20000.0));
            ++period;
        }
        for (double e : widthErr) widthMean += e / static_cast<double>(widthErr.size());
        widthMax = widthErr.empty() ? 0 : *std::max_element(widthErr.begin(), widthErr.end());
        startMax = startErr.empty() ? 0 : *std::max_element(startErr.begin(), startErr.end());
    }
    state.counters["pulse_err_mean_us"] = widthMean;
    state.counters["pulse_err_max_us"] = widthMax;
    state.counters["period_drift_max_us"] = startMax;
    state.counters["sched_fifo"] = realtime ? 1 : 0;
}
BENCHMARK(ServoPulseJitter)->Iterations(1)->Unit(benchmark::kSecond);

void PuppetStep(benchmark::State& state) {
    const auto puppet = output::Puppet::load(findDataFile("puppets/hid-board.toml"));
    const std::vector<std::string> poses{"open", "wide",      "w",           "pbm",        "fv",
                                         "shch", "tongue_up", "tongue_down", "tongue_back"};
    output::PuppetDriver driver(puppet, poses);
    std::vector<float> w(poses.size(), 0.3f);
    double t = 0;
    for (auto _ : state) {
        w[0] = static_cast<float>(0.5 + 0.5 * std::sin(t * 20));
        driver.update(t, w);
        t += 0.01;
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) *
                            static_cast<std::int64_t>(puppet.actuators.size()));
    state.SetLabel("items = actuator commands");
}
BENCHMARK(PuppetStep);

const std::vector<std::string> kPoses{"open", "wide",      "w",           "pbm",        "fv",
                                      "shch", "tongue_up", "tongue_down", "tongue_back"};

// Every channel moving every frame (the worst case: nothing skipped as unchanged).
void driveFrames(benchmark::State& state, output::PuppetDriver& driver, std::size_t channels,
                 const std::function<void()>& every64 = {}) {
    std::vector<float> w(kPoses.size(), 0.3f);
    double t = 0;
    std::int64_t frames = 0;
    for (auto _ : state) {
        const float phase = static_cast<float>(frames % 2);
        for (auto& x : w) x = 0.2f + 0.6f * phase;
        w[2] = 0.8f - 0.6f * phase;  // "w" against "wide": lip corners move too
        driver.update(t, w);
        t += 0.01;
        ++frames;
        if (every64 && frames % 64 == 0) every64();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) *
                            static_cast<std::int64_t>(channels));
    state.SetLabel("items = actuator commands; time = one frame");
}

// I2C wire time of `bytes` written in `transactions` (start, address, data, ack per byte, stop).
double i2cMicroseconds(double bytes, double transactions, double hz) {
    return ((bytes + transactions) * 9 + 2 * transactions) / hz * 1e6;
}

void Pca9685Frame(benchmark::State& state) {
    const auto puppet = output::Puppet::named("pca9685-jaw-lips");
    test::FakePca9685 chip;
    std::size_t bytes = 0;
    struct Counting : output::I2cDevice {
        test::FakePca9685* chip;
        std::size_t* bytes;
        bool write(std::span<const std::uint8_t> b) override {
            *bytes += b.size();
            return chip->write(b);
        }
        bool read(std::uint8_t r, std::span<std::uint8_t> out) override {
            return chip->read(r, out);
        }
    };
    output::PuppetDriver driver(puppet, kPoses);
    driver.addSink(std::make_unique<output::Pca9685Sink>(puppet, 1, 0x40, [&](unsigned, unsigned) {
        auto d = std::make_unique<Counting>();
        d->chip = &chip;
        d->bytes = &bytes;
        return d;
    }));
    const std::vector<float> w(kPoses.size(), 0.0f);
    driver.update(0, w);  // the setup writes, not counted
    bytes = 0;
    const std::size_t setupWrites = chip.writes;
    driveFrames(state, driver, puppet.actuators.size());
    const double frames = static_cast<double>(state.iterations());
    const double perFrame = static_cast<double>(bytes) / frames;
    const double transactions = static_cast<double>(chip.writes - setupWrites) / frames;
    state.counters["i2c_bytes_per_frame"] = perFrame;
    state.counters["i2c_us_per_frame_100kHz"] = i2cMicroseconds(perFrame, transactions, 100e3);
    state.counters["i2c_us_per_frame_400kHz"] = i2cMicroseconds(perFrame, transactions, 400e3);
}
BENCHMARK(Pca9685Frame);

void MaestroFrame(benchmark::State& state) {
    const int master = posix_openpt(O_RDWR | O_NOCTTY);
    grantpt(master);
    unlockpt(master);
    fcntl(master, F_SETFL, O_NONBLOCK);
    const std::string port = ptsname(master);
    std::ifstream in(findDataFile("puppets/maestro-jaw.toml"));
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    text.replace(text.find("/dev/ttyACM0"), 12, port);
    const auto puppet = output::Puppet::load(test::writePuppet("bench-maestro", text));
    output::PuppetDriver driver(puppet, kPoses);
    auto sink = std::make_unique<output::MaestroSink>(puppet, port);
    const auto* maestro = sink.get();
    driver.addSink(std::move(sink));
    std::size_t bytes = 0;
    std::uint8_t buf[65536];
    const auto drain = [&] {
        for (ssize_t n; (n = ::read(master, buf, sizeof buf)) > 0;)
            bytes += static_cast<std::size_t>(n);
    };
    const std::vector<float> w(kPoses.size(), 0.0f);
    driver.update(0, w);
    drain();
    bytes = 0;
    driveFrames(state, driver, puppet.actuators.size(), drain);  // (the reading is timed too)
    drain();
    const double perFrame = static_cast<double>(bytes) / static_cast<double>(state.iterations());
    state.counters["bytes_per_frame"] = perFrame;
    state.counters["ttl_us_per_frame_115200"] = perFrame * 10 / 115200 * 1e6;
    state.counters["frames_dropped"] = static_cast<double>(maestro->framesDropped());
    ::close(master);
}
BENCHMARK(MaestroFrame);

void KernelPwmFrame(benchmark::State& state) {
    const auto root = std::filesystem::temp_directory_path() /
                      ("lipsyncd_bench_pwm_" + std::to_string(::getpid()));
    std::filesystem::create_directories(root / "pwmchip0" / "pwm0");
    std::ofstream(root / "pwmchip0" / "npwm") << "1\n";
    for (const char* attr : {"period", "duty_cycle", "enable"})
        std::ofstream(root / "pwmchip0" / "pwm0" / attr) << "0\n";
    const auto puppet = output::Puppet::named("pwm-jaw");
    {
        output::PuppetDriver driver(puppet, kPoses);
        driver.addSink(std::make_unique<output::KernelPwmSink>(puppet, 0, root));
        driveFrames(state, driver, puppet.actuators.size());
    }
    state.counters["writes_per_frame"] = 1;  // one duty_cycle write per moving channel
    std::filesystem::remove_all(root);
}
BENCHMARK(KernelPwmFrame);

}  // namespace

BENCHMARK_MAIN();
