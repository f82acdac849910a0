// Software servo PWM: every period, all servo lines go high together and each goes low after
// its own pulse width, in order of width. Deadlines are absolute (clock_nanosleep with
// TIMER_ABSTIME on CLOCK_MONOTONIC) so errors do not accumulate; the thread asks for SCHED_FIFO
// and carries on at normal priority where that is not permitted. Pulse widths are atomics: the
// control side never blocks the pulse loop.
#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <lipsyncd/output.hpp>

namespace lipsyncd::output {

namespace {
std::int64_t monotonicNs() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// The kernel wakes a sleeper tens of µs late (more under load), and 11 µs of pulse error is a
// degree of servo travel (notes/hardware.md): sleep to just short of the deadline, then spin
// the last stretch. Spinning 100 µs twice a period costs about 1 % of a core per 50 Hz loop.
constexpr std::int64_t kSpinNs = 100'000;

void sleepUntilNs(std::int64_t deadline) {
    const std::int64_t wake = deadline - kSpinNs;
    timespec ts{static_cast<time_t>(wake / 1'000'000'000), static_cast<long>(wake % 1'000'000'000)};
    if (wake > monotonicNs())
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
        }
    while (monotonicNs() < deadline) {
    }
}
}  // namespace

double ServoPwm::pulseUs(double value, double min, double max, double pulseMinUs,
                         double pulseMaxUs) {
    const double share = std::clamp((value - min) / (max - min), 0.0, 1.0);
    return pulseMinUs + share * (pulseMaxUs - pulseMinUs);
}

ServoPwm::ServoPwm(std::vector<Servo> servos, double frequencyHz, Clock clock, SleepUntil sleep)
    : servos_(std::move(servos)),
      pulseNs_(servos_.size()),
      periodNs_(static_cast<std::int64_t>(1e9 / frequencyHz)),
      clock_(clock ? std::move(clock) : monotonicNs),
      sleep_(sleep ? std::move(sleep) : sleepUntilNs) {
    for (auto& p : pulseNs_) p = 0;  // relaxed until told otherwise
}

ServoPwm::~ServoPwm() {
    running_ = false;
    if (thread_.joinable()) thread_.join();
    for (auto& s : servos_) s.line->set(false);
}

void ServoPwm::set(std::size_t servo, double value, bool active) {
    const auto& s = servos_[servo];
    setPulse(servo, pulseUs(value, s.min, s.max, s.pulseMinUs, s.pulseMaxUs), active);
}

void ServoPwm::setPulse(std::size_t servo, double us, bool active) {
    pulseNs_[servo].store(active ? static_cast<std::int64_t>(us * 1000) : 0,
                          std::memory_order_relaxed);
}

void ServoPwm::period(std::int64_t start) {
    // Fixed-size work, no allocation: at most a handful of servos per puppet.
    constexpr std::size_t kMax = 32;
    std::array<std::pair<std::int64_t, std::size_t>, kMax> ends{};
    std::size_t n = 0;
    for (std::size_t i = 0; i < servos_.size() && n < kMax; ++i) {
        const auto width = pulseNs_[i].load(std::memory_order_relaxed);
        if (width <= 0) continue;
        ends[n++] = {width, i};
        servos_[i].line->set(true);
    }
    std::sort(ends.begin(), ends.begin() + static_cast<std::ptrdiff_t>(n));
    for (std::size_t k = 0; k < n; ++k) {
        sleep_(start + ends[k].first);
        servos_[ends[k].second].line->set(false);
    }
}

void ServoPwm::runPeriods(int periods) {
    std::int64_t start = clock_();
    for (int i = 0; i < periods; ++i) {
        period(start);
        start += periodNs_;
        sleep_(start);
    }
}

void ServoPwm::start() {
    running_ = true;
    thread_ = std::thread([this] {
        sched_param param{};
        param.sched_priority = 50;
        realtime_ = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
        std::int64_t start = clock_();
        while (running_) {
            period(start);
            start += periodNs_;
            const auto now = clock_();
            if (now > start + periodNs_)
                start = now;  // fell far behind (suspend): resync, no burst
            sleep_(start);
        }
    });
}

}  // namespace lipsyncd::output
