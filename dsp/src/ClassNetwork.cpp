// The class heard from a frame: a one-hidden-layer network with a softmax output over the
// classes, trained by cross-entropy; its posteriors over the classes' priors are scaled
// likelihoods (Bourlard & Morgan 1994, the hybrid of a multilayer perceptron and an HMM).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <lipsyncd/dsp.hpp>

#include "HiddenLayer.hpp"
#include "VectorLanes.hpp"

namespace lipsyncd::dsp {

namespace {
network::HiddenLayerView hiddenLayer(const ClassNetwork& net) {
    return {net.inputMean, net.inputScale, net.hiddenWeights, net.hiddenBias, net.slopeFrames};
}

// ln Σ exp(z): the softmax's normaliser, from the largest term so that nothing overflows.
float logSumExp(std::span<const float> z) {
    const float top = *std::max_element(z.begin(), z.end());
    float sum = 0;
    for (float v : z) sum += std::exp(v - top);
    return top + std::log(sum);
}
}  // namespace

// Per frame, the hidden sums as the jaw network's, then the output layer eight classes at a
// time, each block's sums kept in a register while every unit adds to them in turn (a silent
// unit, rectified to 0, adds 0). Each class's sum is taken in the same order as one unit at a
// time would take it, so the result does not depend on the blocks: the last block overlaps the
// one before when the classes are not a multiple of eight, and computes those classes again,
// to the same values. Testing each unit for silence instead was a branch mispredicted about half
// the time, and adding unit by unit into memory waited on its own stores.
// The softmax's normaliser is the same for every class, and only differences between classes
// are used, so it is left out: no exponential in the frame loop.
LIPSYNCD_VECTOR_CLONES void ClassNetwork::scaledLogLikelihoods(std::span<const float> features,
                                                               std::span<float> out,
                                                               std::span<float> scratch,
                                                               float priorScale) const {
    network::hiddenSums(hiddenLayer(*this), features, scratch.data());
    const std::size_t count = outputBias.size(), units = hiddenBias.size();
    for (std::size_t h = 0; h < units; ++h)
        scratch[h] = scratch[h] > 0 ? scratch[h] : 0.0f;  // rectified; not a number: 0
    if (count < kVectorLanes) {
        for (std::size_t c = 0; c < count; ++c) {
            out[c] = outputBias[c] - priorScale * logPrior[c];
            for (std::size_t h = 0; h < units; ++h) out[c] += outputWeights[h][c] * scratch[h];
        }
    } else {
        for (std::size_t block = 0; block < count; block += kVectorLanes) {
            const std::size_t c = std::min(block, count - kVectorLanes);
            FloatLanes sum, prior, weights;
            std::memcpy(&sum, &outputBias[c], sizeof sum);
            std::memcpy(&prior, &logPrior[c], sizeof prior);
            sum -= priorScale * prior;
            for (std::size_t h = 0; h < units; ++h) {
                std::memcpy(&weights, &outputWeights[h][c], sizeof weights);
                sum += weights * scratch[h];
            }
            std::memcpy(&out[c], &sum, sizeof sum);
        }
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

namespace {
// The stored network in training's layout (output weights output by output).
network::TrainedLayers layersOf(const ClassNetwork& net) {
    network::TrainedLayers layers{
        net.inputMean, net.inputScale, net.hiddenWeights, net.hiddenBias, {}, net.outputBias};
    const std::size_t units = net.hiddenUnits(), count = net.classes.size();
    layers.outputWeights.assign(count, std::vector<float>(units));
    for (std::size_t h = 0; h < units; ++h)
        for (std::size_t c = 0; c < count; ++c)
            layers.outputWeights[c][h] = net.outputWeights[h][c];
    return layers;
}

// Trained layers as a network over `classes` (its priors left to the caller).
ClassNetwork networkOf(network::TrainedLayers layers, std::span<const std::string> classes) {
    ClassNetwork net;
    net.classes.assign(classes.begin(), classes.end());
    net.inputMean = std::move(layers.inputMean);
    net.inputScale = std::move(layers.inputScale);
    net.hiddenWeights = std::move(layers.hiddenWeights);
    net.hiddenBias = std::move(layers.hiddenBias);
    // Stored unit by unit (ClassNetwork::outputWeights); trained class by class.
    const std::size_t units = net.hiddenBias.size(), count = classes.size();
    net.outputWeights.assign(units, std::vector<float>(count));
    for (std::size_t c = 0; c < count; ++c)
        for (std::size_t h = 0; h < units; ++h)
            net.outputWeights[h][c] = layers.outputWeights[c][h];
    net.outputBias = std::move(layers.outputBias);
    return net;
}

// Cross-entropy through the softmax: d/dz_c = p_c − [c is the frame's class].
network::TrainedLayers trainOnClasses(std::span<const float> inputs,
                                      std::span<const std::uint16_t> labels, std::size_t count,
                                      std::size_t features, std::size_t units, int epochs,
                                      std::uint32_t seed, const network::TrainingStart& start) {
    const std::size_t rows = labels.size();
    if (features == 0 || rows == 0 || inputs.size() != rows * features || units == 0)
        throw InputError("class network: no training frames");
    for (auto l : labels)
        if (l >= count) throw InputError("class network: a frame's class is out of range");
    return network::trainLayers(
        inputs, rows, features, units, count, epochs, seed, 1.0f,
        [&](std::size_t row, std::span<const float> z, std::span<float> dz) {
            const float norm = logSumExp(z);
            for (std::size_t c = 0; c < count; ++c) dz[c] = std::exp(z[c] - norm);
            dz[labels[row]] -= 1.0f;
        },
        start);
}
}  // namespace

ClassNetwork trainClassNetwork(std::span<const float> inputs, std::span<const std::uint16_t> labels,
                               std::span<const std::string> classes, std::size_t features,
                               int hiddenUnits, int epochs, std::uint32_t seed) {
    const std::size_t rows = labels.size(), count = classes.size();
    auto net = networkOf(
        trainOnClasses(inputs, labels, count, features,
                       static_cast<std::size_t>(std::max(0, hiddenUnits)), epochs, seed, {}),
        classes);
    std::vector<double> frames(count, 0.0);
    for (auto l : labels) frames[l] += 1;
    for (std::size_t c = 0; c < count; ++c)  // a class without frames: as if it had one
        net.logPrior.push_back(
            static_cast<float>(std::log(std::max(1.0, frames[c]) / static_cast<double>(rows))));
    return net;
}

ClassNetwork fineTuneClassNetwork(const ClassNetwork& base, std::span<const float> inputs,
                                  std::span<const std::uint16_t> labels, int epochs, float rate,
                                  std::uint32_t seed) {
    const auto start = layersOf(base);
    auto net = networkOf(trainOnClasses(inputs, labels, base.classes.size(), base.inputMean.size(),
                                        base.hiddenUnits(), epochs, seed, {&start, rate}),
                         base.classes);
    net.logPrior = base.logPrior;
    net.slopeFrames = base.slopeFrames;
    return net;
}

}  // namespace lipsyncd::dsp
