// The networks a template set carries (TemplateSet::jawNetwork, classNetwork) as JSON, read and
// written alike wherever they are kept: the template file, and a speaker's file (the networks a
// show's voice trained further: SpeakerAdaptation).
#pragma once

#include <lipsyncd/dsp.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lipsyncd::dsp {

// Five significant digits: the whitening's entries span orders of magnitude (0.001 to 10).
std::vector<double> precise(const std::vector<float>& v);

// Read: every field present and of its type (InputError naming `source` and the field); sizes
// are checked by the network's validate().
JawNetwork readJawNetwork(const nlohmann::json& j, const std::string& source);
nlohmann::json writeJawNetwork(const JawNetwork& n);
ClassNetwork readClassNetwork(const nlohmann::json& j, const std::string& source);
nlohmann::json writeClassNetwork(const ClassNetwork& n);

}  // namespace lipsyncd::dsp
