// The networks as JSON (NetworkJson.hpp); their fields are described in
// config/templates/README.md.
#include "NetworkJson.hpp"

#include <cstdio>
#include <cstdlib>

#include "JsonField.hpp"

namespace lipsyncd::dsp {

using nlohmann::json;

std::vector<double> precise(const std::vector<float>& v) {
    std::vector<double> out(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
        char text[32];
        std::snprintf(text, sizeof text, "%.5g", static_cast<double>(v[i]));
        out[i] = std::strtod(text, nullptr);
    }
    return out;
}

namespace {
// The hidden layer both networks have (dsp/src/HiddenLayer.hpp): the same fields, read and
// written alike.
template <class Network>
void readHiddenLayer(const json& j, const std::string& p, const std::string& source, Network& n) {
    n.inputMean = member<std::vector<float>>(j, "input_mean", p, source);
    n.inputScale = member<std::vector<float>>(j, "input_scale", p, source);
    n.hiddenWeights = member<std::vector<std::vector<float>>>(j, "hidden_weights", p, source);
    n.hiddenBias = member<std::vector<float>>(j, "hidden_bias", p, source);
    if (j.contains("slope_frames")) n.slopeFrames = member<int>(j, "slope_frames", p, source);
}

template <class Network>
json writeHiddenLayer(const Network& n) {
    json hidden = json::array();
    for (const auto& row : n.hiddenWeights) hidden.push_back(precise(row));
    json j = {{"input_mean", precise(n.inputMean)},
              {"input_scale", precise(n.inputScale)},
              {"hidden_weights", hidden},
              {"hidden_bias", precise(n.hiddenBias)}};
    if (n.slopeFrames > 0) j["slope_frames"] = n.slopeFrames;
    return j;
}

}  // namespace

JawNetwork readJawNetwork(const json& j, const std::string& source) {
    const std::string p = "jaw_network.";
    JawNetwork n;
    readHiddenLayer(j, p, source, n);
    n.outputWeights = member<std::vector<float>>(j, "output_weights", p, source);
    n.outputBias = member<float>(j, "output_bias", p, source);
    return n;
}

json writeJawNetwork(const JawNetwork& n) {
    json j = writeHiddenLayer(n);
    j["output_weights"] = precise(n.outputWeights);
    j["output_bias"] = precise({n.outputBias})[0];
    return j;
}

ClassNetwork readClassNetwork(const json& j, const std::string& source) {
    const std::string p = "class_network.";
    ClassNetwork n;
    n.classes = member<std::vector<std::string>>(j, "classes", p, source);
    readHiddenLayer(j, p, source, n);
    n.outputWeights = member<std::vector<std::vector<float>>>(j, "output_weights", p, source);
    n.outputBias = member<std::vector<float>>(j, "output_bias", p, source);
    n.logPrior = member<std::vector<float>>(j, "log_prior", p, source);
    return n;
}

json writeClassNetwork(const ClassNetwork& n) {
    json j = writeHiddenLayer(n), output = json::array();
    for (const auto& row : n.outputWeights) output.push_back(precise(row));
    j["classes"] = n.classes;
    j["output_weights"] = output;
    j["output_bias"] = precise(n.outputBias);
    j["log_prior"] = precise(n.logPrior);
    return j;
}

}  // namespace lipsyncd::dsp
