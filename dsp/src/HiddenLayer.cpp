#include "HiddenLayer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numeric>
#include <random>
#include <stdexcept>

#include "VectorLanes.hpp"

namespace lipsyncd::dsp::network {

namespace {
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

// Adam's moments for one block of parameters (Kingma & Ba 2015, algorithm 1).
struct AdamBlock {
    std::vector<float> m, v;
    float rate;
    AdamBlock(std::size_t n, float stepSize) : m(n, 0.0f), v(n, 0.0f), rate(stepSize) {}
    void step(std::span<float> params, std::span<const float> grad, int t) {
        constexpr float beta1 = 0.9f, beta2 = 0.999f, epsilon = 1e-8f;
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
void standardise(std::span<const float> inputs, std::size_t features, TrainedLayers& net) {
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

// The parameters while training: hidden weights unit by unit (each unit's row contiguous for
// its dot product), output weights output by output.
struct Parameters {
    std::vector<float> w1, b1, w2, b2;
    std::vector<float> g1, gb1, g2, gb2;
    void clearGradients() {
        for (auto* g : {&g1, &gb1, &g2, &gb2}) std::fill(g->begin(), g->end(), 0.0f);
    }
};

// A trained network's standardisation into `net` and its weights into `p` (training's layout).
void startFrom(const TrainedLayers& from, std::size_t features, std::size_t units,
               std::size_t outputs, TrainedLayers& net, Parameters& p) {
    if (from.inputMean.size() != features || from.hiddenBias.size() != units ||
        from.outputBias.size() != outputs)
        throw std::invalid_argument("trainLayers: the starting network has other sizes");
    net.inputMean = from.inputMean;
    net.inputScale = from.inputScale;
    p.w1.resize(units * features);
    for (std::size_t i = 0; i < features; ++i)
        for (std::size_t h = 0; h < units; ++h) p.w1[h * features + i] = from.hiddenWeights[i][h];
    p.b1 = from.hiddenBias;
    p.w2.resize(outputs * units);
    for (std::size_t o = 0; o < outputs; ++o)
        std::copy(from.outputWeights[o].begin(), from.outputWeights[o].end(),
                  p.w2.begin() + static_cast<std::ptrdiff_t>(o * units));
    p.b2 = from.outputBias;
}
}  // namespace

// The features are standardised once; then eight units at a time keep their sums in a register
// while every feature adds to them in turn, instead of every feature adding to all the units'
// sums in memory (a load and a store per unit and feature). Each unit's sum is taken in the
// same order either way, so the result is the same to the bit; the last block overlaps the one
// before when the units are not a multiple of eight and computes those units again, alike.
LIPSYNCD_VECTOR_CLONES void hiddenSums(const HiddenLayerView& layer,
                                       std::span<const float> features, float* a) {
    const std::size_t units = layer.bias.size();
    const std::size_t n = std::min({features.size(), layer.inputMean.size(), kMaxFeatures});
    std::array<float, kMaxFeatures> x;
    for (std::size_t i = 0; i < n; ++i)
        x[i] = (features[i] - layer.inputMean[i]) * layer.inputScale[i];
    if (units < kVectorLanes) {
        for (std::size_t h = 0; h < units; ++h) {
            a[h] = layer.bias[h];
            for (std::size_t i = 0; i < n; ++i) a[h] += layer.weights[i][h] * x[i];
        }
        return;
    }
    for (std::size_t block = 0; block < units; block += kVectorLanes) {
        const std::size_t h = std::min(block, units - kVectorLanes);
        FloatLanes sum, weights;
        std::memcpy(&sum, &layer.bias[h], sizeof sum);
        for (std::size_t i = 0; i < n; ++i) {
            std::memcpy(&weights, &layer.weights[i][h], sizeof weights);
            sum += weights * x[i];
        }
        std::memcpy(a + h, &sum, sizeof sum);
    }
}

void requireFinite(std::span<const float> values, const std::string& field,
                   const std::string& source) {
    for (std::size_t i = 0; i < values.size(); ++i)
        if (!std::isfinite(values[i]))
            throw InputError(source, 0,
                             field + "[" + std::to_string(i) + "] must be a finite number");
}

void requireSize(std::size_t size, std::size_t expected, const std::string& field,
                 const std::string& source) {
    if (size != expected)
        throw InputError(source, 0,
                         field + " has " + std::to_string(size) + " values, expected " +
                             std::to_string(expected));
}

void validateHiddenLayer(const HiddenLayerView& layer, std::size_t frameFeatures,
                         const std::string& prefix, const std::string& source) {
    if (layer.slopeFrames < 0 || layer.slopeFrames > kMaxSlopeFrames)
        throw InputError(source, 0,
                         prefix + ".slope_frames: must be 0 to " + std::to_string(kMaxSlopeFrames) +
                             " (" + std::to_string(layer.slopeFrames) + ")");
    const std::size_t features = networkInputs(frameFeatures, layer.slopeFrames);
    if (features > kMaxFeatures)
        throw InputError(source, 0,
                         prefix + ": " + std::to_string(features) + " features, at most " +
                             std::to_string(kMaxFeatures));
    const std::size_t units = layer.bias.size();
    if (units == 0 || units > kMaxHiddenUnits)
        throw InputError(source, 0,
                         prefix + ".hidden_bias: 1 to " + std::to_string(kMaxHiddenUnits) +
                             " hidden units, not " + std::to_string(units));
    requireSize(layer.inputMean.size(), features, prefix + ".input_mean", source);
    requireSize(layer.inputScale.size(), features, prefix + ".input_scale", source);
    requireSize(layer.weights.size(), features, prefix + ".hidden_weights", source);
    requireFinite(layer.inputMean, prefix + ".input_mean", source);
    requireFinite(layer.inputScale, prefix + ".input_scale", source);
    requireFinite(layer.bias, prefix + ".hidden_bias", source);
    for (std::size_t i = 0; i < features; ++i) {
        const std::string field = prefix + ".hidden_weights[" + std::to_string(i) + "]";
        requireSize(layer.weights[i].size(), units, field, source);
        requireFinite(layer.weights[i], field, source);
    }
}

TrainedLayers trainLayers(std::span<const float> inputs, std::size_t rows, std::size_t features,
                          std::size_t units, std::size_t outputs, int epochs, std::uint32_t seed,
                          float lossScale, const OutputGradient& gradient,
                          const TrainingStart& start) {
    TrainedLayers net;
    std::mt19937 rng(seed);
    Parameters p;
    if (start.from) {
        startFrom(*start.from, features, units, outputs, net, p);
    } else {
        standardise(inputs, features, net);
        // Hidden weights ~ N(0, 1/features), output weights ~ N(0, 1/units): unit-variance
        // pre-activations from standardised inputs.
        std::normal_distribution<float> normal(0.0f, 1.0f);
        p.w1.resize(units * features);
        p.b1.assign(units, 0.0f);
        p.w2.resize(outputs * units);
        p.b2.assign(outputs, 0.0f);
        for (auto& w : p.w1) w = normal(rng) / std::sqrt(static_cast<float>(features));
        for (auto& w : p.w2) w = normal(rng) / std::sqrt(static_cast<float>(units));
    }
    p.g1.resize(p.w1.size());
    p.gb1.resize(units);
    p.g2.resize(p.w2.size());
    p.gb2.resize(outputs);
    AdamBlock a1(p.w1.size(), start.rate), ab1(units, start.rate), a2(p.w2.size(), start.rate),
        ab2(outputs, start.rate);

    constexpr std::size_t kBatch = 256;
    std::vector<std::size_t> order(rows);
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::vector<float> x(features), hidden(units), z(outputs), dz(outputs);
    int t = 0;
    for (int epoch = 0; epoch < epochs; ++epoch) {
        std::shuffle(order.begin(), order.end(), rng);
        for (std::size_t start = 0; start < rows; start += kBatch) {
            const std::size_t end = std::min(rows, start + kBatch);
            p.clearGradients();
            const float perRow = lossScale / static_cast<float>(end - start);
            for (std::size_t k = start; k < end; ++k) {
                const float* row = &inputs[order[k] * features];
                for (std::size_t i = 0; i < features; ++i)
                    x[i] = (row[i] - net.inputMean[i]) * net.inputScale[i];
                std::copy(p.b2.begin(), p.b2.end(), z.begin());
                for (std::size_t h = 0; h < units; ++h) {
                    hidden[h] = rectify(p.b1[h] + dot(&p.w1[h * features], x.data(), features));
                    for (std::size_t o = 0; o < outputs; ++o)
                        z[o] += p.w2[o * units + h] * hidden[h];
                }
                gradient(order[k], z, dz);
                for (std::size_t o = 0; o < outputs; ++o) {
                    dz[o] *= perRow;
                    p.gb2[o] += dz[o];
                }
                for (std::size_t h = 0; h < units; ++h) {
                    for (std::size_t o = 0; o < outputs; ++o)
                        p.g2[o * units + h] += dz[o] * hidden[h];
                    if (hidden[h] <= 0) continue;
                    float dh = 0;
                    for (std::size_t o = 0; o < outputs; ++o) dh += dz[o] * p.w2[o * units + h];
                    p.gb1[h] += dh;
                    for (std::size_t i = 0; i < features; ++i) p.g1[h * features + i] += dh * x[i];
                }
            }
            ++t;
            a1.step(p.w1, p.g1, t);
            ab1.step(p.b1, p.gb1, t);
            a2.step(p.w2, p.g2, t);
            ab2.step(p.b2, p.gb2, t);
        }
    }
    net.hiddenWeights.assign(features, std::vector<float>(units));
    for (std::size_t i = 0; i < features; ++i)
        for (std::size_t h = 0; h < units; ++h) net.hiddenWeights[i][h] = p.w1[h * features + i];
    net.hiddenBias = std::move(p.b1);
    for (std::size_t o = 0; o < outputs; ++o)
        net.outputWeights.emplace_back(p.w2.begin() + static_cast<std::ptrdiff_t>(o * units),
                                       p.w2.begin() + static_cast<std::ptrdiff_t>((o + 1) * units));
    net.outputBias = std::move(p.b2);
    return net;
}

}  // namespace lipsyncd::dsp::network
