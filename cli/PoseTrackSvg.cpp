#include "PoseTrackSvg.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <ostream>

namespace lipsyncd::cli {

namespace {
constexpr double kLeft = 50, kTop = 20, kLegend = 130, kLabels = 40;
// Distinct colours for up to twelve poses (then they repeat).
constexpr std::array<const char*, 12> kColours{"#d62728", "#1f77b4", "#2ca02c", "#9467bd",
                                               "#ff7f0e", "#8c564b", "#e377c2", "#7f7f7f",
                                               "#bcbd22", "#17becf", "#393b79", "#637939"};

std::string escaped(const std::string& s) {
    std::string out;
    for (char c : s) {
        if (c == '<')
            out += "&lt;";
        else if (c == '>')
            out += "&gt;";
        else if (c == '&')
            out += "&amp;";
        else if (c == '"')
            out += "&quot;";
        else
            out += c;
    }
    return out;
}

struct Frame {
    double t0, t1, width, height;
    double x(double t) const { return kLeft + (t - t0) / (t1 - t0) * width; }
    double y(double v) const { return kTop + (1 - v) * height; }
};

void axes(std::ostream& out, const Frame& f) {
    out << "<g stroke=\"#999\" stroke-width=\"1\">\n";
    for (double v : {0.0, 0.5, 1.0})
        out << "<line x1=\"" << kLeft << "\" y1=\"" << f.y(v) << "\" x2=\"" << kLeft + f.width
            << "\" y2=\"" << f.y(v) << "\" stroke-dasharray=\"" << (v == 0 ? "none" : "3,3")
            << "\"/>\n";
    out << "</g>\n<g font-family=\"sans-serif\" font-size=\"11\" fill=\"#333\">\n";
    for (double v : {0.0, 0.5, 1.0})
        out << "<text x=\"" << kLeft - 6 << "\" y=\"" << f.y(v) + 4 << "\" text-anchor=\"end\">"
            << v << "</text>\n";
    const double step = f.t1 - f.t0 > 5 ? 1.0 : 0.1 * std::ceil((f.t1 - f.t0) / 1.0);
    for (double t = std::ceil(f.t0 / step) * step; t <= f.t1 + 1e-9; t += step)
        out << "<text x=\"" << f.x(t) << "\" y=\"" << f.y(0) + kLabels - 4
            << "\" text-anchor=\"middle\">" << t << " s</text>\n";
    out << "</g>\n";
}

void phonemes(std::ostream& out, const Frame& f, const PhonemeSchedule& schedule) {
    out << "<g class=\"phonemes\" font-family=\"monospace\" font-size=\"11\" fill=\"#000\">\n";
    for (const auto& s : schedule) {
        out << "<line x1=\"" << f.x(s.start) << "\" y1=\"" << kTop << "\" x2=\"" << f.x(s.start)
            << "\" y2=\"" << f.y(0) + 18 << "\" stroke=\"#ccc\"/>\n";
        out << "<text x=\"" << f.x((s.start + s.end) / 2) << "\" y=\"" << f.y(0) + 15
            << "\" text-anchor=\"middle\">" << escaped(s.phoneme) << "</text>\n";
    }
    out << "</g>\n";
}

void curves(std::ostream& out, const Frame& f, const PoseTrack& track) {
    for (std::size_t p = 0; p < track.poses.size(); ++p) {
        out << "<polyline class=\"pose\" data-pose=\"" << escaped(track.poses[p])
            << "\" fill=\"none\" stroke=\"" << kColours[p % kColours.size()]
            << "\" stroke-width=\"1.5\" points=\"";
        for (std::size_t i = 0; i < track.frames(); ++i)
            out << f.x(track.times[i]) << ',' << f.y(std::clamp(track.frame(i)[p], 0.0f, 1.0f))
                << ' ';
        out << "\"/>\n";
        const double ly = kTop + 14 * static_cast<double>(p) + 8;
        out << "<line x1=\"" << kLeft + f.width + 12 << "\" y1=\"" << ly << "\" x2=\""
            << kLeft + f.width + 32 << "\" y2=\"" << ly << "\" stroke=\""
            << kColours[p % kColours.size()] << "\" stroke-width=\"3\"/>"
            << "<text x=\"" << kLeft + f.width + 38 << "\" y=\"" << ly + 4
            << "\" font-family=\"sans-serif\" font-size=\"11\">" << escaped(track.poses[p])
            << "</text>\n";
    }
}
}  // namespace

void writePoseTrackSvg(std::ostream& out, const PoseTrack& track, const PhonemeSchedule* schedule,
                       const SvgChartOptions& options) {
    double t0 = track.frames() ? track.times.front() : 0,
           t1 = track.frames() ? track.times.back() : 1;
    if (schedule && !schedule->empty()) {
        t0 = std::min(t0, schedule->front().start);
        t1 = std::max(t1, schedule->back().end);
    }
    if (!(t1 > t0)) t1 = t0 + 1;
    const Frame f{t0, t1, (t1 - t0) * options.pixelsPerSecond, options.plotHeight};
    out << std::fixed << std::setprecision(1);
    out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kLeft + f.width + kLegend
        << "\" height=\"" << kTop + f.height + kLabels + 10
        << "\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    axes(out, f);
    if (schedule) phonemes(out, f, *schedule);
    curves(out, f, track);
    out << "</svg>\n";
}

}  // namespace lipsyncd::cli
