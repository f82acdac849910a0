// What the jaw network and the class network share: one hidden layer of rectified units over
// standardised frame features (Bourlard & Morgan 1994, a multilayer perceptron on acoustic
// frames), its evaluation, its training by Adam (Kingma & Ba 2015), and the checks of its fields
// when a template file is read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <lipsyncd/dsp.hpp>
#include <span>
#include <string>
#include <vector>

namespace lipsyncd::dsp::network {

// Features: up to 512 spectrum bins and the extras (AnalysisConfig::validate).
inline constexpr std::size_t kMaxFeatures = 520;
inline constexpr std::size_t kMaxHiddenUnits = 256;

// Rectified linear units: as good as tanh on the real dev speakers (frame jaw r 0.86 / 0.75 /
// 0.75 against 0.85 / 0.75 / 0.74) and no transcendental function per unit in the frame loop.
inline float rectify(float a) {
    return a > 0 ? a : 0.0f;
}

// The hidden layer as stored: weights feature by feature (one feature's weights to every unit
// side by side), so that the frame loop vectorises without reordering any sum.
struct HiddenLayerView {
    std::span<const float> inputMean, inputScale;
    std::span<const std::vector<float>> weights;  // per feature: its weight to each unit
    std::span<const float> bias;                  // per unit
    int slopeFrames = 0;                          // the network's: its inputs (networkInputs)
};

// The hidden units' sums (before rectifying) into a[0 .. units).
void hiddenSums(const HiddenLayerView& layer, std::span<const float> features, float* a);

// InputError naming `source` and the field (prefix + name) when the layer's slopes are out of
// range, its sizes disagree with the inputs frames of `features` features give, or a value is
// not finite.
void validateHiddenLayer(const HiddenLayerView& layer, std::size_t features,
                         const std::string& prefix, const std::string& source);
void requireSize(std::size_t size, std::size_t expected, const std::string& field,
                 const std::string& source);
void requireFinite(std::span<const float> values, const std::string& field,
                   const std::string& source);

// A trained network: the layer in its stored layout, and the output layer per output, unit.
struct TrainedLayers {
    std::vector<float> inputMean, inputScale;
    std::vector<std::vector<float>> hiddenWeights;  // per feature: per unit
    std::vector<float> hiddenBias;
    std::vector<std::vector<float>> outputWeights;  // per output: per unit
    std::vector<float> outputBias;                  // per output
};

// The gradient of one row's loss with respect to the output sums `z`, into `dz` (both one value
// per output), given the row's index.
using OutputGradient =
    std::function<void(std::size_t row, std::span<const float> z, std::span<float> dz)>;

// Where training starts: from weights drawn from the seed over inputs standardised on their own
// (`from` null), or from a trained network, its standardisation and weights kept (fine-tuning:
// `units` and `outputs` must be its sizes). `rate`: Adam's step size.
struct TrainingStart {
    const TrainedLayers* from = nullptr;
    float rate = 1e-3f;
};

// Trains the layers on `inputs` (rows × features values): mini-batches of 256 in an order fixed
// by `seed`, Adam on the gradient `gradient` gives per row, times `lossScale` over the batch's
// rows, from `start`.
TrainedLayers trainLayers(std::span<const float> inputs, std::size_t rows, std::size_t features,
                          std::size_t units, std::size_t outputs, int epochs, std::uint32_t seed,
                          float lossScale, const OutputGradient& gradient,
                          const TrainingStart& start = {});

}  // namespace lipsyncd::dsp::network
