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

// The time of the output after one at q + phase/L: M/L later, as a whole part and a phase (no
// division per output).
struct OutputClock {
    std::int64_t q;
    int phase;
    std::int64_t step;
    int stepPhase, up;
    static OutputClock at(std::int64_t q, int phase, int up, int down) {
        return {q, phase, down / up, down % up, up};
    }
    void advance() {
        q += step;
        phase += stepPhase;
        if (phase >= up) phase -= up, ++q;
    }
};

struct FilterRun {
    const float* coefs;
    std::size_t taps;
    int up, down;
    const float* buffer;  // input from absolute index `bufferStart` on
    std::int64_t bufferStart, half;
    float* out;
    // The taps of the output at `clock`, and its input window (half − 1 samples before its time
    // to `taps` − half after).
    const float* tapsAt(const OutputClock& clock) const {
        return coefs + static_cast<std::size_t>(clock.phase) * taps;
    }
    const float* windowAt(const OutputClock& clock) const {
        return buffer + (clock.q - half + 1 - bufferStart);
    }
};

// The sum of the lanes, as a tree (three dependent adds, not seven).
[[gnu::always_inline]] inline float laneSum(const FloatLanes& v) {
    float half[kVectorLanes / 2], quarter[kVectorLanes / 4];
    for (std::size_t i = 0; i < kVectorLanes / 2; ++i) half[i] = v[i] + v[i + kVectorLanes / 2];
    for (std::size_t i = 0; i < kVectorLanes / 4; ++i) quarter[i] = half[i] + half[i + 2];
    return quarter[0] + quarter[1];
}

// K dot products of one phase's taps `c` with K input windows `stride` samples apart from `x`,
// written `outStride` apart. The taps' vectors go alternately into two partial sums, added last,
// for any K: an output is the same bit for bit whichever K computed it.
template <std::size_t K>
[[gnu::always_inline]] inline void windowDots(const float* c, const float* x, std::size_t stride,
                                              std::size_t taps, float* out, std::size_t outStride) {
    FloatLanes even[K] = {}, odd[K] = {};
    std::size_t j = 0;
    for (; j + 2 * kVectorLanes <= taps; j += 2 * kVectorLanes) {
        FloatLanes a, b;
        std::memcpy(&a, c + j, sizeof a);
        std::memcpy(&b, c + j + kVectorLanes, sizeof b);
#pragma GCC unroll 4
        for (std::size_t k = 0; k < K; ++k) {
            FloatLanes u, v;
            std::memcpy(&u, x + k * stride + j, sizeof u);
            std::memcpy(&v, x + k * stride + j + kVectorLanes, sizeof v);
            even[k] += a * u;
            odd[k] += b * v;
        }
    }
    if (j < taps) {
        FloatLanes a;
        std::memcpy(&a, c + j, sizeof a);
        for (std::size_t k = 0; k < K; ++k) {
            FloatLanes u;
            std::memcpy(&u, x + k * stride + j, sizeof u);
            even[k] += a * u;
        }
    }
    for (std::size_t k = 0; k < K; ++k) out[k * outStride] = laneSum(even[k] + odd[k]);
}

// `count` outputs from output time q + phase/L on, each the dot product of its phase's taps with
// its input window. Outputs n, n + L, n + 2L, n + 3L have the same phase and windows M samples
// apart: in whole groups of 4L outputs each load of a phase's taps serves four (2.3 times
// faster than one at a time); what is left over (and 10 ms live blocks) goes one at a time.
LIPSYNCD_VECTOR_CLONES void runFilter(const FilterRun& r, std::int64_t q, int phase,
                                      std::size_t count) {
    constexpr std::size_t kGroup = 4;
    auto clock = OutputClock::at(q, phase, r.up, r.down);
    const auto up = static_cast<std::size_t>(r.up), down = static_cast<std::size_t>(r.down);
    std::size_t n = 0;
    for (; n + kGroup * up <= count; n += kGroup * up) {
        auto first = clock;
        for (std::size_t i = 0; i < up; ++i, first.advance())
            windowDots<kGroup>(r.tapsAt(first), r.windowAt(first), down, r.taps, r.out + n + i, up);
        clock.q += static_cast<std::int64_t>(kGroup * down);  // L outputs later: M samples
    }
    for (; n < count; ++n, clock.advance())
        windowDots<1>(r.tapsAt(clock), r.windowAt(clock), 0, r.taps, r.out + n, 0);
}
}  // namespace

// The filter a spec asks for at these rates: edges in cycles per input sample, the window's
// shape, its half length and the taps a phase holds (rounded up to whole vectors).
struct PolyphaseResampler::Shape {
    double pass, stop, beta;
    std::int64_t half;
    std::size_t taps;
};

PolyphaseResampler::Shape PolyphaseResampler::shapeFor(double inputRate, double outputRate,
                                                       const LowPassSpec& spec) {
    const double nyquist = std::min(inputRate, outputRate) / 2;
    Shape f{};
    f.pass = spec.passbandEnd * nyquist / inputRate;
    f.stop = spec.stopbandBegin * nyquist / inputRate;
    f.beta = kaiserBeta(spec.attenuationDb);
    f.half = kaiserHalfLength(spec.attenuationDb, f.stop - f.pass);
    f.taps =
        (static_cast<std::size_t>(2 * f.half) + kVectorLanes - 1) / kVectorLanes * kVectorLanes;
    return f;
}

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
    const Shape shape = shapeFor(inputRate, outputRate, spec);
    if (static_cast<std::size_t>(up) * shape.taps > kMaxCoefficients) return std::nullopt;
    return PolyphaseResampler(up, down, shape, maxBlock);
}

PolyphaseResampler::PolyphaseResampler(int up, int down, const Shape& shape, std::size_t maxBlock)
    : up_(up), down_(down), taps_(shape.taps), half_(shape.half), maxBlock_(maxBlock) {
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
    auto clock = OutputClock::at(q_, phase_, up_, down_);
    std::size_t count = 0;
    // Output q + phase/L reads input q − half + 1 .. q − half + taps.
    for (; clock.q - half_ + 1 + static_cast<std::int64_t>(taps_) <= available && clock.q < end;
         clock.advance())
        ++count;
    const FilterRun run{coefs_.data(),  taps_,        up_,   down_,
                        buffer_.data(), bufferStart_, half_, out_.data()};
    runFilter(run, q_, phase_, count);
    produced_ = count;
    q_ = clock.q;
    phase_ = clock.phase;
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
    std::int64_t end = std::numeric_limits<std::int64_t>::max();
    if (flush && input.empty()) {
        // The input ends: zeros after it, and outputs only up to its last sample's time.
        end = bufferStart_ + static_cast<std::int64_t>(buffered_);
        std::fill_n(buffer_.begin() + static_cast<std::ptrdiff_t>(buffered_), taps_, 0.0f);
        buffered_ += taps_;
        ended_ = true;
    }
    produce(bufferStart_ + static_cast<std::int64_t>(buffered_), end);
    dropConsumed();
    return {out_.data(), produced_};
}

}  // namespace lipsyncd::dsp
