#include "PolyphaseResampler.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "VectorLanes.hpp"

namespace lipsyncd::dsp {

namespace {
// Beyond these the tables outgrow a cache and libsoxr's multi-stage design is the better tool.
constexpr int kMaxPhases = 2048;
constexpr std::size_t kMaxCoefficients = std::size_t{1} << 19;

// Kaiser's formulas for a window meeting `attenuationDb` over a transition `width` (cycles per
// input sample): its shape β and its length (Kaiser 1974; Oppenheim & Schafer 2010, §7.5).
double kaiserBeta(double a) {
    if (a > 50) return 0.1102 * (a - 8.7);
    if (a >= 21) return 0.5842 * std::pow(a - 21, 0.4) + 0.07886 * (a - 21);
    return 0;
}

std::int64_t kaiserHalfLength(double a, double width) {
    const double length = std::ceil((a - 7.95) / (14.36 * width));
    return std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(length / 2)));
}

// The modified Bessel function I0 by its power series Σ ((x/2)^k / k!)², each term the last
// times (x/2)²/k² (1/k² from a table): for the β of the attenuations used here (under 12) the
// terms fall below a double's rounding well within 40. libstdc++'s std::cyl_bessel_i took about
// a microsecond a call, 80 ms to design a filter from 22.05 kHz; this takes 3 ms.
constexpr int kBesselTerms = 40;
constexpr auto kInverseSquares = [] {
    std::array<double, kBesselTerms> inverse{};
    for (int k = 1; k < kBesselTerms; ++k) inverse[k] = 1.0 / (static_cast<double>(k) * k);
    return inverse;
}();

double besselI0(double x) {
    const double q = x * x / 4;
    double term = 1, sum = 1;
    for (int k = 1; k < kBesselTerms && term > 1e-17 * sum; ++k) {
        term *= q * kInverseSquares[k];
        sum += term;
    }
    return sum;
}

// The windowed sinc at τ input samples from its centre, cut-off `fc` in cycles per input sample:
// unit gain at DC whether it decimates or interpolates, since it is sampled once per input.
struct KaiserSinc {
    double fc, beta, half, i0Beta;
    double operator()(double tau) const {
        const double x = 2 * fc * tau;
        const double sinc = x == 0 ? 1.0 : std::sin(M_PI * x) / (M_PI * x);
        const double r = tau / half;
        const double window = r * r >= 1 ? 0.0 : besselI0(beta * std::sqrt(1 - r * r)) / i0Beta;
        return 2 * fc * sinc * window;
    }
};

struct FilterRun {
    const float* coefs;
    std::size_t taps;
    int up, down;
    const float* buffer;  // input from absolute index `bufferStart` on
    std::int64_t bufferStart, half;
    float* out;
};

// The sum of the lanes, as a tree (three dependent adds, not seven).
[[gnu::always_inline]] inline float laneSum(const FloatLanes& v) {
    float half[kVectorLanes / 2], quarter[kVectorLanes / 4];
    for (std::size_t i = 0; i < kVectorLanes / 2; ++i) half[i] = v[i] + v[i + kVectorLanes / 2];
    for (std::size_t i = 0; i < kVectorLanes / 4; ++i) quarter[i] = half[i] + half[i + 2];
    return quarter[0] + quarter[1];
}

// The time of the output after one at q + phase/L: M/L later, as a whole part and a phase (no
// division per output).
struct OutputClock {
    std::int64_t q;
    int phase;
    std::int64_t step;
    int stepPhase, up;
    void advance() {
        q += step;
        phase += stepPhase;
        if (phase >= up) phase -= up, ++q;
    }
};

// Outputs n, n + L, n + 2L, n + 3L have the same phase, and their windows lie M samples apart:
// each load of the phase's taps serves all four, which halves the loads the dot products wait on.
// Writes L·kGroup outputs from `clock` on.
constexpr std::size_t kGroup = 4;
[[gnu::always_inline]] inline void samePhaseOutputs(const FilterRun& r, OutputClock clock,
                                                    float* out) {
    const auto up = static_cast<std::size_t>(r.up);
    for (std::size_t i = 0; i < up; ++i, clock.advance()) {
        const float* c = r.coefs + static_cast<std::size_t>(clock.phase) * r.taps;
        const float* x = r.buffer + (clock.q - r.half + 1 - r.bufferStart);
        // Summed as oneOutput sums: the same output whichever path made it.
        FloatLanes even[kGroup] = {}, odd[kGroup] = {};
        std::size_t j = 0;
        for (; j + 2 * kVectorLanes <= r.taps; j += 2 * kVectorLanes) {
            FloatLanes a, b;
            std::memcpy(&a, c + j, sizeof a);
            std::memcpy(&b, c + j + kVectorLanes, sizeof b);
#pragma GCC unroll 4
            for (std::size_t k = 0; k < kGroup; ++k) {
                FloatLanes u, v;
                const float* xk = x + k * static_cast<std::size_t>(r.down) + j;
                std::memcpy(&u, xk, sizeof u);
                std::memcpy(&v, xk + kVectorLanes, sizeof v);
                even[k] += a * u;
                odd[k] += b * v;
            }
        }
        if (j < r.taps) {
            FloatLanes a;
            std::memcpy(&a, c + j, sizeof a);
            for (std::size_t k = 0; k < kGroup; ++k) {
                FloatLanes u;
                std::memcpy(&u, x + k * static_cast<std::size_t>(r.down) + j, sizeof u);
                even[k] += a * u;
            }
        }
        for (std::size_t k = 0; k < kGroup; ++k) out[i + k * up] = laneSum(even[k] + odd[k]);
    }
}

// One output at a time, for what is left over from whole groups (and 10 ms live blocks).
[[gnu::always_inline]] inline float oneOutput(const FilterRun& r, const OutputClock& clock) {
    const float* c = r.coefs + static_cast<std::size_t>(clock.phase) * r.taps;
    const float* x = r.buffer + (clock.q - r.half + 1 - r.bufferStart);
    FloatLanes even = {}, odd = {};
    std::size_t j = 0;
    for (; j + 2 * kVectorLanes <= r.taps; j += 2 * kVectorLanes) {
        FloatLanes a, b, u, v;
        std::memcpy(&a, c + j, sizeof a);
        std::memcpy(&u, x + j, sizeof u);
        std::memcpy(&b, c + j + kVectorLanes, sizeof b);
        std::memcpy(&v, x + j + kVectorLanes, sizeof v);
        even += a * u;
        odd += b * v;
    }
    if (j < r.taps) {
        FloatLanes a, u;
        std::memcpy(&a, c + j, sizeof a);
        std::memcpy(&u, x + j, sizeof u);
        even += a * u;
    }
    return laneSum(even + odd);
}

// `count` outputs from output time q + phase/L on, each the dot product of its phase's taps with
// the input window that ends `half` samples past its time.
LIPSYNCD_VECTOR_CLONES void runFilter(const FilterRun& r, std::int64_t q, int phase,
                                      std::size_t count) {
    OutputClock clock{q, phase, r.down / r.up, r.down % r.up, r.up};
    const std::size_t group = kGroup * static_cast<std::size_t>(r.up);
    std::size_t n = 0;
    for (; n + group <= count; n += group) {
        samePhaseOutputs(r, clock, r.out + n);
        clock.q += static_cast<std::int64_t>(kGroup) * r.down;  // L outputs later: M samples
    }
    for (; n < count; ++n, clock.advance()) r.out[n] = oneOutput(r, clock);
}
}  // namespace

namespace {
// The filter a spec asks for at these rates: edges in cycles per input sample, the window's
// shape, its half length and the taps a phase holds (rounded up to whole vectors).
struct FilterShape {
    double pass, stop, beta;
    std::int64_t half;
    std::size_t taps;
};

FilterShape shapeFor(double inputRate, double outputRate, const LowPassSpec& spec) {
    const double nyquist = std::min(inputRate, outputRate) / 2;
    FilterShape f{};
    f.pass = spec.passbandEnd * nyquist / inputRate;
    f.stop = spec.stopbandBegin * nyquist / inputRate;
    f.beta = kaiserBeta(spec.attenuationDb);
    f.half = kaiserHalfLength(spec.attenuationDb, f.stop - f.pass);
    f.taps =
        (static_cast<std::size_t>(2 * f.half) + kVectorLanes - 1) / kVectorLanes * kVectorLanes;
    return f;
}
}  // namespace

std::optional<PolyphaseResampler> PolyphaseResampler::create(double inputRate, double outputRate,
                                                             const LowPassSpec& spec,
                                                             std::size_t maxBlock) {
    const auto whole = [](double r) { return r >= 1 && r <= 1e6 && r == std::round(r); };
    if (!whole(inputRate) || !whole(outputRate)) return std::nullopt;
    const auto in = static_cast<std::int64_t>(inputRate),
               out = static_cast<std::int64_t>(outputRate);
    const std::int64_t g = std::gcd(in, out);
    const auto up = static_cast<int>(out / g), down = static_cast<int>(in / g);
    if (up > kMaxPhases) return std::nullopt;
    const FilterShape shape = shapeFor(inputRate, outputRate, spec);
    if (static_cast<std::size_t>(up) * shape.taps > kMaxCoefficients) return std::nullopt;
    return PolyphaseResampler(up, down, spec, inputRate, maxBlock);
}

PolyphaseResampler::PolyphaseResampler(int up, int down, const LowPassSpec& spec, double inputRate,
                                       std::size_t maxBlock)
    : up_(up), down_(down), maxBlock_(maxBlock) {
    const FilterShape shape = shapeFor(inputRate, inputRate * up / down, spec);
    half_ = shape.half;
    taps_ = shape.taps;
    const auto span = static_cast<std::size_t>(2 * half_);
    coefs_.assign(static_cast<std::size_t>(up) * taps_, 0.0f);
    // Phase p serves the outputs that fall p/L of a sample past an input; tap j weighs the
    // input half − 1 − j samples before that point (after it, for j ≥ half). Each phase is
    // scaled to a DC gain of exactly 1, so no phase is louder than the next.
    const KaiserSinc h{(shape.pass + shape.stop) / 2, shape.beta, static_cast<double>(half_),
                       besselI0(shape.beta)};
    std::vector<double> phase(span);
    for (int p = 0; p < up; ++p) {
        double sum = 0;
        for (std::size_t j = 0; j < span; ++j) {
            const double tau = static_cast<double>(p) / up + static_cast<double>(half_) - 1.0 -
                               static_cast<double>(j);
            phase[j] = h(tau);
            sum += phase[j];
        }
        float* c = coefs_.data() + static_cast<std::size_t>(p) * taps_;
        for (std::size_t j = 0; j < span; ++j) c[j] = static_cast<float>(phase[j] / sum);
    }
    // The window of output 0 starts half − 1 samples before the input does: zeros.
    bufferStart_ = 1 - half_;
    buffered_ = static_cast<std::size_t>(half_ - 1);
    buffer_.assign(maxBlock + 3 * taps_ + static_cast<std::size_t>(down / up) + 16, 0.0f);
    const double perInput = static_cast<double>(up) / down;
    out_.resize(
        static_cast<std::size_t>(std::ceil(static_cast<double>(maxBlock + 3 * taps_) * perInput)) +
        4);
}

void PolyphaseResampler::append(std::span<const float> input) {
    std::copy(input.begin(), input.end(), buffer_.begin() + static_cast<std::ptrdiff_t>(buffered_));
    buffered_ += input.size();
}

// Every output whose window lies within the buffer (it ends before absolute index `available`)
// and, when the input has ended, whose time is before its end (q + phase/L < `end`).
void PolyphaseResampler::produce(std::int64_t available, std::int64_t end) {
    const std::int64_t step = down_ / up_;
    const int stepPhase = down_ % up_;
    std::int64_t q = q_;
    int phase = phase_;
    std::size_t count = 0;
    // Output q + phase/L reads input q − half + 1 .. q − half + taps.
    while (q - half_ + 1 + static_cast<std::int64_t>(taps_) <= available && q < end) {
        ++count;
        q += step;
        phase += stepPhase;
        if (phase >= up_) phase -= up_, ++q;
    }
    const FilterRun run{coefs_.data(),  taps_,        up_,   down_,
                        buffer_.data(), bufferStart_, half_, out_.data()};
    runFilter(run, q_, phase_, count);
    produced_ = count;
    q_ = q;
    phase_ = phase;
}

void PolyphaseResampler::dropConsumed() {
    const std::int64_t start = q_ - half_ + 1;
    const auto shift = static_cast<std::size_t>(
        std::clamp<std::int64_t>(start - bufferStart_, 0, static_cast<std::int64_t>(buffered_)));
    if (shift == 0) return;
    std::memmove(buffer_.data(), buffer_.data() + shift, (buffered_ - shift) * sizeof(float));
    buffered_ -= shift;
    bufferStart_ += static_cast<std::int64_t>(shift);
}

std::span<const float> PolyphaseResampler::process(std::span<const float> input, bool flush) {
    if (ended_) return {};
    if (input.size() > maxBlock_) throw std::logic_error("resampler: block larger than maxBlock");
    append(input);
    inputCount_ += static_cast<std::int64_t>(input.size());
    std::int64_t end = std::numeric_limits<std::int64_t>::max();
    if (flush && input.empty()) {
        // The input ends: zeros after it, and outputs only up to its last sample's time.
        std::fill_n(buffer_.begin() + static_cast<std::ptrdiff_t>(buffered_), taps_, 0.0f);
        buffered_ += taps_;
        end = inputCount_;
        ended_ = true;
    }
    produce(bufferStart_ + static_cast<std::int64_t>(buffered_), end);
    dropConsumed();
    return {out_.data(), produced_};
}

}  // namespace lipsyncd::dsp
