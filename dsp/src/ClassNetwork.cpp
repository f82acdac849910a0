// The class heard from a frame: a one-hidden-layer network with a softmax output over the
// classes, trained by cross-entropy; its posteriors over the classes' priors are scaled
// likelihoods (Bourlard & Morgan 1994, the hybrid of a multilayer perceptron and an HMM).
#include <algorithm>
#include <cmath>
#include <lipsyncd/dsp.hpp>

#include "HiddenLayer.hpp"
#include "VectorLanes.hpp"

namespace lipsyncd::dsp {

namespace {
network::HiddenLayerView hiddenLayer(const ClassNetwork& net) {
    return {net.inputMean, net.inputScale, net.hiddenWeights, net.hiddenBias};
}

// ln Σ exp(z): the softmax's normaliser, from the largest term so that nothing overflows.
float logSumExp(std::span<const float> z) {
    const float top = *std::max_element(z.begin(), z.end());
    float sum = 0;
    for (float v : z) sum += std::exp(v - top);
    return top + std::log(sum);
}
}  // namespace

// Per frame, the hidden sums as the jaw network's, then the output layer unit by unit: a silent
// (rectified to 0) unit is skipped, and each unit's weights to the classes lie side by side.
// The softmax's normaliser is the same for every class, and only differences between classes
// are used, so it is left out: no exponential in the frame loop.
LIPSYNCD_VECTOR_CLONES void ClassNetwork::scaledLogLikelihoods(std::span<const float> features,
                                                               std::span<float> out,
                                                               std::span<float> scratch,
                                                               float priorScale) const {
    network::hiddenSums(hiddenLayer(*this), features, scratch.data());
    const std::size_t count = outputBias.size();
    for (std::size_t c = 0; c < count; ++c) out[c] = outputBias[c] - priorScale * logPrior[c];
    for (std::size_t h = 0; h < hiddenBias.size(); ++h) {
        const float a = scratch[h];
        if (!(a > 0)) continue;  // rectified to 0 (or not a number: nothing to add)
        const float* w = outputWeights[h].data();
        for (std::size_t c = 0; c < count; ++c) out[c] += w[c] * a;
    }
    for (std::size_t c = 0; c < count; ++c)
        if (!std::isfinite(out[c])) out[c] = 0;
}

std::vector<int> ClassNetwork::setIndices(const PhonemeSet& set) const {
    std::vector<int> indices;
    for (const auto& name : classes) {
        const auto idx = set.find(name);
        indices.push_back(idx ? static_cast<int>(*idx) : -1);
    }
    return indices;
}

void ClassNetwork::addToDistances(std::span<const float> features, std::span<const int> setIndices,
                                  float dbPerNat, float priorScale, std::span<float> distances,
                                  std::span<float> likelihoods, std::span<float> scratch) const {
    scaledLogLikelihoods(features, likelihoods, scratch, priorScale);
    const float best = *std::max_element(likelihoods.begin(), likelihoods.end());
    for (std::size_t o = 0; o < likelihoods.size(); ++o) {
        const int c = setIndices[o];
        if (c >= 0 && std::isfinite(distances[c]))
            distances[c] += dbPerNat * (best - likelihoods[o]);
    }
}

void ClassNetwork::validate(std::size_t features, const std::string& source) const {
    network::validateHiddenLayer(hiddenLayer(*this), features, "class_network", source);
    const std::size_t units = hiddenBias.size(), count = classes.size();
    if (count < 2) throw InputError(source, 0, "class_network.classes: at least 2 classes");
    network::requireSize(outputWeights.size(), units, "class_network.output_weights", source);
    network::requireSize(outputBias.size(), count, "class_network.output_bias", source);
    network::requireSize(logPrior.size(), count, "class_network.log_prior", source);
    network::requireFinite(outputBias, "class_network.output_bias", source);
    network::requireFinite(logPrior, "class_network.log_prior", source);
    for (std::size_t h = 0; h < units; ++h) {
        const std::string field = "class_network.output_weights[" + std::to_string(h) + "]";
        network::requireSize(outputWeights[h].size(), count, field, source);
        network::requireFinite(outputWeights[h], field, source);
    }
}

ClassNetwork trainClassNetwork(std::span<const float> inputs, std::span<const std::uint16_t> labels,
                               std::span<const std::string> classes, std::size_t features,
                               int hiddenUnits, int epochs, std::uint32_t seed) {
    const std::size_t rows = labels.size(), count = classes.size();
    if (features == 0 || rows == 0 || inputs.size() != rows * features || hiddenUnits <= 0)
        throw InputError("class network: no training frames");
    std::vector<double> frames(count, 0.0);
    for (auto l : labels) {
        if (l >= count) throw InputError("class network: a frame's class is out of range");
        frames[l] += 1;
    }
    // Cross-entropy through the softmax: d/dz_c = p_c − [c is the frame's class].
    auto layers = network::trainLayers(
        inputs, rows, features, static_cast<std::size_t>(hiddenUnits), count, epochs, seed, 1.0f,
        [&](std::size_t row, std::span<const float> z, std::span<float> dz) {
            const float norm = logSumExp(z);
            for (std::size_t c = 0; c < count; ++c) dz[c] = std::exp(z[c] - norm);
            dz[labels[row]] -= 1.0f;
        });
    ClassNetwork net;
    net.classes.assign(classes.begin(), classes.end());
    net.inputMean = std::move(layers.inputMean);
    net.inputScale = std::move(layers.inputScale);
    net.hiddenWeights = std::move(layers.hiddenWeights);
    net.hiddenBias = std::move(layers.hiddenBias);
    // Stored unit by unit (ClassNetwork::outputWeights); trained class by class.
    const auto units = static_cast<std::size_t>(hiddenUnits);
    net.outputWeights.assign(units, std::vector<float>(count));
    for (std::size_t c = 0; c < count; ++c)
        for (std::size_t h = 0; h < units; ++h)
            net.outputWeights[h][c] = layers.outputWeights[c][h];
    net.outputBias = std::move(layers.outputBias);
    for (std::size_t c = 0; c < count; ++c)  // a class without frames: as if it had one
        net.logPrior.push_back(
            static_cast<float>(std::log(std::max(1.0, frames[c]) / static_cast<double>(rows))));
    return net;
}

}  // namespace lipsyncd::dsp
