// Pose weights as CSV (DESIGN.md "File formats"): header `time,<pose>,...`, a row per frame.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <lipsyncd/core.hpp>

namespace lipsyncd {

std::optional<std::size_t> PoseTrack::pose(std::string_view name) const {
    const auto it = std::find(poses.begin(), poses.end(), name);
    if (it == poses.end()) return std::nullopt;
    return static_cast<std::size_t>(it - poses.begin());
}

void PoseTrack::append(double time, std::span<const float> weights) {
    if (weights.size() != poses.size())
        throw std::invalid_argument("PoseTrack::append: wrong number of weights");
    times.push_back(time);
    values.insert(values.end(), weights.begin(), weights.end());
}

namespace {
std::vector<std::string_view> splitCsv(std::string_view line) {
    std::vector<std::string_view> out;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    std::size_t start = 0;
    for (;;) {
        const auto comma = line.find(',', start);
        auto field =
            line.substr(start, comma == std::string_view::npos ? line.npos : comma - start);
        while (!field.empty() && field.front() == ' ') field.remove_prefix(1);
        while (!field.empty() && field.back() == ' ') field.remove_suffix(1);
        out.push_back(field);
        if (comma == std::string_view::npos) return out;
        start = comma + 1;
    }
}

// What a file may hold: times within a day (anything that steps through the track would
// otherwise run for ever), weights finite within ±kMaxWeight (they are 0 .. 1 by design).
constexpr double kMaxSeconds = 86400;
constexpr double kMaxWeight = 10;

double parseNumber(std::string_view text, const std::string& source, std::size_t line,
                   const std::string& column) {
    double v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size())
        throw InputError(source, line,
                         "column '" + column + "': '" + std::string(text) + "' is not a number");
    return v;
}
}  // namespace

PoseTrack readPoseTrackCsv(std::istream& in, const std::string& sourceName) {
    PoseTrack track;
    std::string text;
    std::size_t lineNo = 0;
    if (!std::getline(in, text)) throw InputError(sourceName, 0, "empty: expected a CSV header");
    ++lineNo;
    const auto header = splitCsv(text);
    if (header.empty() || header[0] != "time")
        throw InputError(sourceName, 1, "header must start with 'time' (time,<pose>,<pose>,...)");
    if (header.size() < 2) throw InputError(sourceName, 1, "header names no poses");
    for (std::size_t i = 1; i < header.size(); ++i) {
        if (header[i].empty())
            throw InputError(sourceName, 1, "empty pose name in column " + std::to_string(i + 1));
        if (track.pose(header[i]))
            throw InputError(sourceName, 1, "pose '" + std::string(header[i]) + "' appears twice");
        track.poses.emplace_back(header[i]);
    }
    std::vector<float> row(track.poses.size());
    while (std::getline(in, text)) {
        ++lineNo;
        if (text.empty() || text == "\r") continue;
        const auto fields = splitCsv(text);
        if (fields.size() != header.size())
            throw InputError(sourceName, lineNo,
                             "expected " + std::to_string(header.size()) + " columns, found " +
                                 std::to_string(fields.size()));
        const double t = parseNumber(fields[0], sourceName, lineNo, "time");
        if (!std::isfinite(t) || t < 0 || t > kMaxSeconds)
            throw InputError(sourceName, lineNo, "time must be finite, within 0 .. 86400 s");
        if (!track.times.empty() && t <= track.times.back())
            throw InputError(sourceName, lineNo,
                             "time " + std::string(fields[0]) + " does not increase");
        for (std::size_t p = 0; p < row.size(); ++p) {
            const double w = parseNumber(fields[p + 1], sourceName, lineNo, track.poses[p]);
            if (!(std::abs(w) <= kMaxWeight))  // NaN too
                throw InputError(sourceName, lineNo,
                                 "column '" + track.poses[p] + "': " + std::string(fields[p + 1]) +
                                     " is not a finite weight within -10 .. 10");
            row[p] = static_cast<float>(w);
        }
        track.append(t, row);
    }
    return track;
}

PoseTrack readPoseTrackCsvFile(const std::filesystem::path& file) {
    if (file == "-") return readPoseTrackCsv(std::cin, "<stdin>");
    std::ifstream in(file);
    if (!in) throw InputError(file.string() + ": cannot open");
    return readPoseTrackCsv(in, file.string());
}

void writePoseTrackCsv(std::ostream& out, const PoseTrack& track) {
    out << "time";
    for (const auto& p : track.poses) out << ',' << p;
    out << '\n' << std::fixed;
    for (std::size_t f = 0; f < track.frames(); ++f) {
        out << std::setprecision(3) << track.times[f];
        for (float v : track.frame(f)) out << ',' << std::setprecision(4) << v;
        out << '\n';
    }
}

}  // namespace lipsyncd
