// The jaw heard from a frame: a one-hidden-layer network over the frame's features (Bourlard &
// Morgan 1994, a multilayer perceptron on acoustic frames), its evaluation and its training.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <lipsyncd/dsp.hpp>
#include <numeric>
#include <random>

#include "VectorLanes.hpp"

namespace lipsyncd::dsp {

namespace {
// Features: up to 512 spectrum bins and the extras (AnalysisConfig::validate).
constexpr std::size_t kMaxFeatures = 520;
constexpr std::size_t kMaxHiddenUnits = 256;

// Rectified linear units: as good as tanh on the real dev speakers (frame jaw r 0.86 / 0.75 /
// 0.75 against 0.85 / 0.75 / 0.74) and no transcendental function per unit in the frame loop.
float rectify(float a) {
    return a > 0 ? a : 0.0f;
}
float logistic(float z) {
    return 1.0f / (1.0f + std::exp(-z));
}

// Σ a[i]·b[i] in eight lanes, then the lanes summed: a fixed order, the same sum on every run.
float dot(const float* a, const float* b, std::size_t n) {
    FloatLanes acc = {};
    std::size_t i = 0;
    for (; i + kVectorLanes <= n; i += kVectorLanes) {
        FloatLanes x, y;
        std::memcpy(&x, a + i, sizeof x);
        std::memcpy(&y, b + i, sizeof y);
        acc += x * y;
    }
    float sum = 0;
    for (std::size_t l = 0; l < kVectorLanes; ++l) sum += acc[l];
    for (; i < n; ++i) sum += a[i] * b[i];
    return sum;
}

void requireFinite(std::span<const float> values, const std::string& field,
                   const std::string& source) {
    for (std::size_t i = 0; i < values.size(); ++i)
        if (!std::isfinite(values[i]))
            throw InputError(
                source, 0,
                "jaw_network." + field + "[" + std::to_string(i) + "] must be a finite number");
}

void requireSize(std::size_t size, std::size_t expected, const std::string& field,
                 const std::string& source) {
    if (size != expected)
        throw InputError(source, 0,
                         "jaw_network." + field + " has " + std::to_string(size) +
                             " values, expected " + std::to_string(expected));
}

// The hidden units' sums, feature by feature: one feature's weights to every unit lie side by
// side, so the inner loop vectorises without reordering any sum.
LIPSYNCD_VECTOR_CLONES void hiddenSums(const JawNetwork& net, std::span<const float> features,
                                       float* a) {
    const std::size_t units = net.hiddenBias.size();
    std::copy(net.hiddenBias.begin(), net.hiddenBias.end(), a);
    const std::size_t n = std::min(features.size(), net.inputMean.size());
    for (std::size_t i = 0; i < n; ++i) {
        const float x = (features[i] - net.inputMean[i]) * net.inputScale[i];
        const float* w = net.hiddenWeights[i].data();
        for (std::size_t h = 0; h < units; ++h) a[h] += w[h] * x;
    }
}
}  // namespace

float JawNetwork::operator()(std::span<const float> features) const {
    std::array<float, kMaxHiddenUnits> a;
    hiddenSums(*this, features, a.data());
    const std::size_t units = hiddenBias.size();
    float z = outputBias;
    for (std::size_t h = 0; h < units; ++h) z += outputWeights[h] * rectify(a[h]);
    const float jaw = logistic(z);
    return std::isfinite(jaw) ? jaw : 0.0f;
}

void JawNetwork::validate(std::size_t features, const std::string& source) const {
    if (features > kMaxFeatures)
        throw InputError(source, 0,
                         "jaw_network: " + std::to_string(features) + " features, at most " +
                             std::to_string(kMaxFeatures));
    const std::size_t units = hiddenBias.size();
    if (units == 0 || units > kMaxHiddenUnits)
        throw InputError(source, 0,
                         "jaw_network.hidden_bias: 1 to " + std::to_string(kMaxHiddenUnits) +
                             " hidden units, not " + std::to_string(units));
    requireSize(inputMean.size(), features, "input_mean", source);
    requireSize(inputScale.size(), features, "input_scale", source);
    requireSize(hiddenWeights.size(), features, "hidden_weights", source);
    requireSize(outputWeights.size(), units, "output_weights", source);
    requireFinite(inputMean, "input_mean", source);
    requireFinite(inputScale, "input_scale", source);
    requireFinite(hiddenBias, "hidden_bias", source);
    requireFinite(outputWeights, "output_weights", source);
    requireFinite(std::span<const float>(&outputBias, 1), "output_bias", source);
    for (std::size_t i = 0; i < features; ++i) {
        const std::string field = "hidden_weights[" + std::to_string(i) + "]";
        requireSize(hiddenWeights[i].size(), units, field, source);
        requireFinite(hiddenWeights[i], field, source);
    }
}

namespace {
// Adam's moments for one block of parameters (Kingma & Ba 2015, algorithm 1).
struct AdamBlock {
    std::vector<float> m, v;
    explicit AdamBlock(std::size_t n) : m(n, 0.0f), v(n, 0.0f) {}
    void step(std::span<float> params, std::span<const float> grad, int t) {
        constexpr float rate = 1e-3f, beta1 = 0.9f, beta2 = 0.999f, epsilon = 1e-8f;
        const float c1 = 1 - std::pow(beta1, static_cast<float>(t));
        const float c2 = 1 - std::pow(beta2, static_cast<float>(t));
        for (std::size_t i = 0; i < params.size(); ++i) {
            m[i] = beta1 * m[i] + (1 - beta1) * grad[i];
            v[i] = beta2 * v[i] + (1 - beta2) * grad[i] * grad[i];
            params[i] -= rate * (m[i] / c1) / (std::sqrt(v[i] / c2) + epsilon);
        }
    }
};

// Per feature: mean and 1 / standard deviation of the inputs (a constant feature keeps scale 1).
void standardise(std::span<const float> inputs, std::size_t features, JawNetwork& net) {
    const std::size_t rows = inputs.size() / features;
    std::vector<double> sum(features, 0.0), squares(features, 0.0);
    for (std::size_t r = 0; r < rows; ++r)
        for (std::size_t i = 0; i < features; ++i) {
            const double x = inputs[r * features + i];
            sum[i] += x;
            squares[i] += x * x;
        }
    net.inputMean.resize(features);
    net.inputScale.resize(features);
    for (std::size_t i = 0; i < features; ++i) {
        const double mean = sum[i] / static_cast<double>(rows);
        const double variance = squares[i] / static_cast<double>(rows) - mean * mean;
        net.inputMean[i] = static_cast<float>(mean);
        net.inputScale[i] = variance > 1e-12 ? static_cast<float>(1 / std::sqrt(variance)) : 1.0f;
    }
}
}  // namespace

JawNetwork trainJawNetwork(std::span<const float> inputs, std::span<const float> targets,
                           std::size_t features, int hiddenUnits, int epochs, std::uint32_t seed) {
    const std::size_t rows = targets.size(), units = static_cast<std::size_t>(hiddenUnits);
    if (features == 0 || rows == 0 || inputs.size() != rows * features || units == 0)
        throw InputError("jaw network: no training frames");
    JawNetwork net;
    standardise(inputs, features, net);

    // Hidden weights ~ N(0, 1/features), output weights ~ N(0, 1/units): unit-variance
    // pre-activations from standardised inputs.
    std::mt19937 rng(seed);
    std::normal_distribution<float> normal(0.0f, 1.0f);
    std::vector<float> w1(units * features), b1(units, 0.0f), w2(units), b2(1, 0.0f);
    for (auto& w : w1) w = normal(rng) / std::sqrt(static_cast<float>(features));
    for (auto& w : w2) w = normal(rng) / std::sqrt(static_cast<float>(units));
    AdamBlock a1(w1.size()), ab1(b1.size()), a2(w2.size()), ab2(1);

    constexpr std::size_t kBatch = 256;
    std::vector<std::size_t> order(rows);
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::vector<float> x(features), hidden(units), g1(w1.size()), gb1(units), g2(units), gb2(1);
    int t = 0;
    for (int epoch = 0; epoch < epochs; ++epoch) {
        std::shuffle(order.begin(), order.end(), rng);
        for (std::size_t start = 0; start < rows; start += kBatch) {
            const std::size_t end = std::min(rows, start + kBatch);
            std::fill(g1.begin(), g1.end(), 0.0f);
            std::fill(gb1.begin(), gb1.end(), 0.0f);
            std::fill(g2.begin(), g2.end(), 0.0f);
            gb2[0] = 0;
            const float perRow = 2.0f / static_cast<float>(end - start);  // d(mean squared error)
            for (std::size_t k = start; k < end; ++k) {
                const float* row = &inputs[order[k] * features];
                for (std::size_t i = 0; i < features; ++i)
                    x[i] = (row[i] - net.inputMean[i]) * net.inputScale[i];
                float z = b2[0];
                for (std::size_t h = 0; h < units; ++h) {
                    hidden[h] = rectify(b1[h] + dot(&w1[h * features], x.data(), features));
                    z += w2[h] * hidden[h];
                }
                const float y = logistic(z);
                const float dz = (y - targets[order[k]]) * y * (1 - y) * perRow;
                gb2[0] += dz;
                for (std::size_t h = 0; h < units; ++h) {
                    g2[h] += dz * hidden[h];
                    if (hidden[h] <= 0) continue;
                    const float dh = dz * w2[h];
                    gb1[h] += dh;
                    for (std::size_t i = 0; i < features; ++i) g1[h * features + i] += dh * x[i];
                }
            }
            ++t;
            a1.step(w1, g1, t);
            ab1.step(b1, gb1, t);
            a2.step(w2, g2, t);
            ab2.step(b2, gb2, t);
        }
    }
    // Stored feature by feature (JawNetwork::hiddenWeights); trained unit by unit.
    net.hiddenWeights.assign(features, std::vector<float>(units));
    for (std::size_t i = 0; i < features; ++i)
        for (std::size_t h = 0; h < units; ++h) net.hiddenWeights[i][h] = w1[h * features + i];
    net.hiddenBias = std::move(b1);
    net.outputWeights = std::move(w2);
    net.outputBias = b2[0];
    return net;
}

}  // namespace lipsyncd::dsp
