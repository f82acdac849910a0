// Output benchmarks (issue 4): software servo PWM pulse jitter against a fake GPIO line that
// timestamps every edge with CLOCK_MONOTONIC (on a board, add the line write's own cost), and
// the cost of one actuator step for a puppet.
//
//   build/bench/output_bench
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <lipsyncd/output.hpp>
#include <thread>

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

}  // namespace

BENCHMARK_MAIN();
