#include <gtest/gtest.h>

#include <cmath>
#include <lipsyncd/dsp.hpp>
#include <random>

using namespace lipsyncd::dsp;

namespace {
// Solves the Toeplitz normal equations R a = −r directly (Gaussian elimination with pivoting).
std::vector<double> directSolve(const std::vector<float>& r, int p) {
    std::vector<std::vector<double>> m(p, std::vector<double>(p + 1));
    for (int i = 0; i < p; ++i) {
        for (int j = 0; j < p; ++j) m[i][j] = r[std::abs(i - j)];
        m[i][p] = -r[i + 1];
    }
    for (int c = 0; c < p; ++c) {
        int pivot = c;
        for (int i = c + 1; i < p; ++i)
            if (std::abs(m[i][c]) > std::abs(m[pivot][c])) pivot = i;
        std::swap(m[c], m[pivot]);
        for (int i = 0; i < p; ++i) {
            if (i == c) continue;
            const double f = m[i][c] / m[c][c];
            for (int j = c; j <= p; ++j) m[i][j] -= f * m[c][j];
        }
    }
    std::vector<double> a(p);
    for (int i = 0; i < p; ++i) a[i] = m[i][p] / m[i][i];
    return a;
}

std::vector<float> autocorrelation(const std::vector<float>& x, int p) {
    std::vector<float> r(p + 1, 0.0f);
    for (int lag = 0; lag <= p; ++lag) {
        double acc = 0;
        for (std::size_t i = lag; i < x.size(); ++i) acc += static_cast<double>(x[i]) * x[i - lag];
        r[lag] = static_cast<float>(acc / x.size());
    }
    return r;
}

// x[n] = −Σ a[i] x[n−i] + e[n]: an AR process whose inverse filter is A(z).
std::vector<float> arProcess(const std::vector<double>& a, std::size_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.1);
    std::vector<float> x(n, 0.0f);
    for (std::size_t t = 0; t < n; ++t) {
        double v = noise(rng);
        for (std::size_t i = 1; i < a.size() && i <= t; ++i) v -= a[i] * x[t - i];
        x[t] = static_cast<float>(v);
    }
    return x;
}
}  // namespace

TEST(LevinsonDurbin, MatchesADirectSolveOfTheNormalEquations) {
    std::mt19937 rng(7);
    std::normal_distribution<float> noise;
    for (int trial = 0; trial < 20; ++trial) {
        std::vector<float> x(400);
        float previous = 0;
        for (auto& v : x) v = previous = 0.8f * previous + noise(rng);  // coloured noise
        const int p = 12;
        const auto r = autocorrelation(x, p);
        const auto lpc = levinsonDurbin(r, p);
        const auto direct = directSolve(r, p);
        ASSERT_TRUE(lpc.stable);
        ASSERT_EQ(lpc.order, p);
        for (int i = 0; i < p; ++i)
            EXPECT_NEAR(lpc.a[i + 1], direct[i], 1e-3) << "a[" << i + 1 << "]";
    }
}

TEST(LevinsonDurbin, RecoversTheCoefficientsOfAKnownArProcess) {
    // Two resonances: poles at radius 0.95 (500 Hz) and 0.9 (1500 Hz) at 10 kHz.
    auto resonator = [](double radius, double hz) {
        return std::vector<double>{1.0, -2 * radius * std::cos(2 * M_PI * hz / 10000),
                                   radius * radius};
    };
    const auto a1 = resonator(0.95, 500), a2 = resonator(0.9, 1500);
    std::vector<double> a(5, 0.0);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) a[i + j] += a1[i] * a2[j];
    const auto x = arProcess(a, 200000, 3);
    const auto lpc = levinsonDurbin(autocorrelation(x, 4), 4);
    for (int i = 1; i <= 4; ++i) EXPECT_NEAR(lpc.a[i], a[i], 0.02) << "a[" << i << "]";
    // The prediction error is the driving noise power (0.1²), relative to the signal power.
    EXPECT_NEAR(lpc.predictionError, 0.01, 0.001);
}

TEST(LevinsonDurbin, ReflectionCoefficientsStayInsideTheUnitInterval) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1, 1);
    for (int trial = 0; trial < 200; ++trial) {
        std::vector<float> x(256);
        for (auto& v : x) v = u(rng) * (trial % 2 ? 1.0f : 1e-4f);
        const auto lpc = levinsonDurbin(autocorrelation(x, 16), 16);
        for (int i = 0; i < lpc.order; ++i) {
            EXPECT_GT(lpc.k[i], -1.0f);
            EXPECT_LT(lpc.k[i], 1.0f);
        }
        EXPECT_GT(lpc.normalizedError, 0.0f);
        EXPECT_LE(lpc.normalizedError, 1.0f);
    }
}

TEST(LevinsonDurbin, RefusesDegenerateInputWithoutNaN) {
    const std::vector<float> zero(13, 0.0f);
    const auto silent = levinsonDurbin(zero, 12);
    EXPECT_FALSE(silent.stable);
    EXPECT_EQ(silent.a[0], 1.0f);
    EXPECT_EQ(silent.a[1], 0.0f);
    std::vector<float> nan(13, std::nanf(""));
    const auto bad = levinsonDurbin(nan, 12);
    EXPECT_FALSE(bad.stable);
    for (float v : bad.a) EXPECT_FALSE(std::isnan(v));
    // A constant signal: r[i] = r[0] for all lags, so k = −1 at once.
    const std::vector<float> constant(13, 1.0f);
    const auto flat = levinsonDurbin(constant, 12);
    EXPECT_FALSE(flat.stable);
    EXPECT_FALSE(std::isnan(flat.normalizedError));
}
