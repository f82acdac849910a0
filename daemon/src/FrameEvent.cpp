#include "FrameEvent.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <nlohmann/json.hpp>

namespace lipsyncd::daemon {

namespace {
// The longest number to_chars writes: sign, 17 digits, point, exponent.
constexpr std::size_t kMaxNumber = 32;

std::string key(const std::string& name) {
    return nlohmann::json(name).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) +
           ":";
}

template <class T>
void number(std::string& out, T v) {
    if (!std::isfinite(v)) {
        out += "null";
        return;
    }
    std::array<char, kMaxNumber> buf{};
    const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
    out.append(buf.data(), r.ptr);
}

float valueOf(float v) {
    return v;
}
double valueOf(const output::ActuatorCommand& c) {
    return c.value;
}

template <class T>
void object(std::string& out, const std::vector<std::string>& keys, std::span<const T> values) {
    out += '{';
    for (std::size_t i = 0; i < values.size() && i < keys.size(); ++i) {
        if (i) out += ',';
        out += keys[i];
        number(out, valueOf(values[i]));
    }
    out += '}';
}
}  // namespace

void FrameEventWriter::setNames(std::span<const std::string> poses,
                                std::span<const std::string> actuators) {
    poseKeys_.clear();
    actuatorKeys_.clear();
    std::size_t longest = 128;  // the fixed text and the time and position
    for (const auto& p : poses) longest += (poseKeys_.emplace_back(key(p))).size() + kMaxNumber + 1;
    for (const auto& a : actuators)
        longest += (actuatorKeys_.emplace_back(key(a))).size() + kMaxNumber + 1;
    line_.reserve(longest);
}

std::string_view FrameEventWriter::format(double time, std::span<const float> weights,
                                          std::span<const output::ActuatorCommand> actuators,
                                          std::optional<double> position) {
    line_.clear();  // keeps its capacity
    line_ += R"({"event":"frame","time":)";
    number(line_, time);
    line_ += R"(,"weights":)";
    object(line_, poseKeys_, weights);
    line_ += R"(,"actuators":)";
    object(line_, actuatorKeys_, actuators);
    if (position) {
        line_ += R"(,"position":)";
        number(line_, *position);
    }
    line_ += "}\n";
    return line_;
}

}  // namespace lipsyncd::daemon
