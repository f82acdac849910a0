#include "GroupConfusion.hpp"

#include <algorithm>
#include <iomanip>
#include <ostream>

namespace lipsyncd::cli {

GroupConfusion GroupConfusion::of(const dsp::ScheduleScore& score, const PhonemeSet& set) {
    GroupConfusion c;
    c.groups = set.groups();
    c.frames.assign(c.groups.size(), std::vector<std::size_t>(c.groups.size(), 0));
    std::vector<std::size_t> groupOf;  // per class of the set: its group's index
    for (std::size_t cls = 0; cls < set.size(); ++cls)
        groupOf.push_back(static_cast<std::size_t>(
            std::find(c.groups.begin(), c.groups.end(), set[cls].group) - c.groups.begin()));
    for (std::size_t r = 0; r < score.confusion.size() && r < set.size(); ++r)
        for (std::size_t h = 0; h < score.confusion[r].size() && h < set.size(); ++h)
            c.frames[groupOf[r]][groupOf[h]] += score.confusion[r][h];
    return c;
}

std::size_t GroupConfusion::labelled(std::size_t group) const {
    std::size_t n = 0;
    for (auto f : frames[group]) n += f;
    return n;
}

std::size_t GroupConfusion::total() const {
    std::size_t n = 0;
    for (std::size_t g = 0; g < groups.size(); ++g) n += labelled(g);
    return n;
}

void printGroupConfusion(std::ostream& out, const std::string& title, const GroupConfusion& c) {
    const auto all = static_cast<double>(c.total());
    if (all == 0) return;
    constexpr int kColumn = 10;
    out << title << " (rows: the labels' group and its share of the frames; columns: % of the row "
        << "heard as each group; lost: points of visual-group accuracy)\n"
        << std::left << std::setw(12) << "  labelled" << std::right << std::setw(7) << "share";
    for (const auto& g : c.groups) out << std::setw(kColumn) << g.substr(0, kColumn - 1);
    out << std::setw(7) << "lost" << '\n' << std::fixed << std::setprecision(1);
    for (std::size_t r = 0; r < c.groups.size(); ++r) {
        const auto n = static_cast<double>(c.labelled(r));
        if (n == 0) continue;
        out << "  " << std::left << std::setw(10) << c.groups[r].substr(0, 9) << std::right
            << std::setw(6) << 100 * n / all << '%';
        for (std::size_t h = 0; h < c.groups.size(); ++h)
            out << std::setw(kColumn) << 100 * c.frames[r][h] / n;
        out << std::setw(7) << 100 * (n - c.frames[r][r]) / all << '\n';
    }
}

nlohmann::json groupConfusionJson(const GroupConfusion& c) {
    auto j = nlohmann::json::object();
    for (std::size_t r = 0; r < c.groups.size(); ++r)
        for (std::size_t h = 0; h < c.groups.size(); ++h)
            if (c.frames[r][h] > 0) j[c.groups[r]][c.groups[h]] = c.frames[r][h];
    return j;
}

}  // namespace lipsyncd::cli
