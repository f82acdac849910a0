// Where one speaker's frames go between the visual groups (silence, open, mid, rounded, ...):
// rows the group the labels give, columns the group heard. The per-class table of `lipsync eval`
// pools every speaker; this says, for the speaker whose figure counts, which of its groups lose
// the most of its accuracy, and to what.
#pragma once

#include <cstddef>
#include <iosfwd>
#include <lipsyncd/core.hpp>
#include <lipsyncd/dsp.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lipsyncd::cli {

struct GroupConfusion {
    std::vector<std::string> groups;               // the set's groups, in first-seen order
    std::vector<std::vector<std::size_t>> frames;  // [labelled group][heard group]

    // Folds a score's class confusion into the set's groups.
    static GroupConfusion of(const dsp::ScheduleScore& score, const PhonemeSet& set);
    std::size_t total() const;
    std::size_t labelled(std::size_t group) const;  // frames whose labels say `group`
};

// The table: per labelled group its share of the frames, where its frames were heard (% of the
// row) and how many points of the speaker's visual-group accuracy the row loses.
void printGroupConfusion(std::ostream& out, const std::string& title, const GroupConfusion& c);

// {labelled: {heard: frames}}, groups with no frames left out.
nlohmann::json groupConfusionJson(const GroupConfusion& c);

}  // namespace lipsyncd::cli
