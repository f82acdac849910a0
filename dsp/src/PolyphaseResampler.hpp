// Rational-ratio resampling by a polyphase FIR (Crochiere & Rabiner 1983, ch. 3): the front end's
// usual conversions (8, 16, 22.05, 44.1, 48 kHz → 10 kHz) are L/M ratios with few phases, and one
// linear-phase filter per phase does them with a few ms of delay where libsoxr holds back tens
// (bench/frontend_bench Resample10ms, delay_ms), and from 16 kHz in less time per frame. The
// filter is a Kaiser-windowed sinc (Kaiser 1974) designed from a passband edge, a stopband edge
// and an attenuation. StreamResampler uses it where the ratio is rational and its tables small,
// and libsoxr elsewhere. Allocates only at construction; process() reuses its buffers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace lipsyncd::dsp {

struct LowPassSpec {
    double attenuationDb;  // in the stopband
    double passbandEnd;    // fraction of the lower of the two Nyquist frequencies
    double stopbandBegin;  // the same; above 1 lets the band's top few per cent alias a little
};

class PolyphaseResampler {
  public:
    // Null when the rates are not whole numbers of Hz or the ratio needs more phases or
    // coefficients than a small table holds (the caller then uses libsoxr).
    static std::optional<PolyphaseResampler> create(double inputRate, double outputRate,
                                                    const LowPassSpec& spec, std::size_t maxBlock);

    // Resamples one block (at most maxBlock samples); the output stays valid until the next
    // call. With `flush` the input ends: what is held back comes out, the end padded with zeros.
    std::span<const float> process(std::span<const float> input, bool flush);

    std::size_t tapsPerPhase() const { return taps_; }
    int phases() const { return up_; }

  private:
    struct Shape;
    static Shape shapeFor(double inputRate, double outputRate, const LowPassSpec& spec);
    PolyphaseResampler(int up, int down, const Shape& shape, std::size_t maxBlock);
    void append(std::span<const float> input);
    void produce(std::int64_t available, std::int64_t end);
    void dropConsumed();

    int up_, down_;              // L and M: output n lies at input time n·M/L
    std::size_t taps_ = 0;       // per phase, a multiple of the vector width
    std::int64_t half_ = 0;      // output n reads input from ⌊n·M/L⌋ − half + 1 on
    std::vector<float> coefs_;   // phase-major: coefs_[p·taps + j]
    std::vector<float> buffer_;  // input from absolute index bufferStart_ on
    std::size_t buffered_ = 0;
    std::int64_t bufferStart_ = 0;  // bufferStart_ + buffered_: input samples taken so far
    std::int64_t q_ = 0;            // the next output's time, ⌊n·M/L⌋ ...
    int phase_ = 0;                 // ... and n·M mod L
    bool ended_ = false;
    std::vector<float> out_;
    std::size_t produced_ = 0;
    std::size_t maxBlock_;
};

}  // namespace lipsyncd::dsp
