// The jaw heard from a frame: a one-hidden-layer network over the frame's features (Bourlard &
// Morgan 1994, a multilayer perceptron on acoustic frames), its evaluation and its training.
#include <algorithm>
#include <array>
#include <cmath>
#include <lipsyncd/dsp.hpp>

#include "HiddenLayer.hpp"

namespace lipsyncd::dsp {

namespace {
float logistic(float z) {
    return 1.0f / (1.0f + std::exp(-z));
}

network::HiddenLayerView hiddenLayer(const JawNetwork& net) {
    return {net.inputMean, net.inputScale, net.hiddenWeights, net.hiddenBias, net.slopeFrames};
}
}  // namespace

float JawNetwork::operator()(std::span<const float> inputs) const {
    std::array<float, network::kMaxHiddenUnits> a;
    network::hiddenSums(hiddenLayer(*this), inputs, a.data());
    const std::size_t units = hiddenBias.size();
    float z = outputBias;
    for (std::size_t h = 0; h < units; ++h) z += outputWeights[h] * network::rectify(a[h]);
    const float jaw = logistic(z);
    return std::isfinite(jaw) ? jaw : 0.0f;
}

void JawNetwork::validate(std::size_t features, const std::string& source) const {
    network::validateHiddenLayer(hiddenLayer(*this), features, "jaw_network", source);
    network::requireSize(outputWeights.size(), hiddenBias.size(), "jaw_network.output_weights",
                         source);
    network::requireFinite(outputWeights, "jaw_network.output_weights", source);
    network::requireFinite(std::span<const float>(&outputBias, 1), "jaw_network.output_bias",
                           source);
}

namespace {
// Squared error through the logistic output: d/dz (y − t)² = 2 (y − t) y (1 − y).
JawNetwork trainOnHeights(std::span<const float> inputs, std::span<const float> targets,
                          std::size_t features, std::size_t units, int epochs, std::uint32_t seed,
                          const network::TrainingStart& start) {
    const std::size_t rows = targets.size();
    if (features == 0 || rows == 0 || inputs.size() != rows * features || units == 0)
        throw InputError("jaw network: no training frames");
    auto layers = network::trainLayers(
        inputs, rows, features, units, 1, epochs, seed, 2.0f,
        [&](std::size_t row, std::span<const float> z, std::span<float> dz) {
            const float y = logistic(z[0]);
            dz[0] = (y - targets[row]) * y * (1 - y);
        },
        start);
    JawNetwork net;
    net.inputMean = std::move(layers.inputMean);
    net.inputScale = std::move(layers.inputScale);
    net.hiddenWeights = std::move(layers.hiddenWeights);
    net.hiddenBias = std::move(layers.hiddenBias);
    net.outputWeights = std::move(layers.outputWeights.front());
    net.outputBias = layers.outputBias.front();
    return net;
}
}  // namespace

JawNetwork trainJawNetwork(std::span<const float> inputs, std::span<const float> targets,
                           std::size_t features, int hiddenUnits, int epochs, std::uint32_t seed) {
    return trainOnHeights(inputs, targets, features,
                          static_cast<std::size_t>(std::max(0, hiddenUnits)), epochs, seed, {});
}

JawNetwork fineTuneJawNetwork(const JawNetwork& base, std::span<const float> inputs,
                              std::span<const float> targets, int epochs, float rate,
                              std::uint32_t seed) {
    const network::TrainedLayers start{base.inputMean,  base.inputScale,      base.hiddenWeights,
                                       base.hiddenBias, {base.outputWeights}, {base.outputBias}};
    auto net = trainOnHeights(inputs, targets, base.inputMean.size(), base.hiddenUnits(), epochs,
                              seed, {&start, rate});
    net.slopeFrames = base.slopeFrames;
    return net;
}

}  // namespace lipsyncd::dsp
