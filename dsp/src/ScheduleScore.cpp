// Scoring a schedule against reference labels, frame by frame.
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {

void ScheduleScore::add(const ScheduleScore& other) {
    frames += other.frames;
    correct += other.correct;
    groupCorrect += other.groupCorrect;
    if (confusion.empty()) {
        confusion = other.confusion;
        return;
    }
    for (std::size_t r = 0; r < confusion.size() && r < other.confusion.size(); ++r)
        for (std::size_t h = 0; h < confusion[r].size(); ++h)
            confusion[r][h] += other.confusion[r][h];
}

namespace {
// The class of the segment covering time t, walking forward with a cursor.
std::size_t classAt(const PhonemeSchedule& s, double t, std::size_t& cursor,
                    const PhonemeSet& set) {
    while (cursor < s.size() && s[cursor].end <= t) ++cursor;
    if (cursor >= s.size() || s[cursor].start > t) return set.silence();
    return set.find(s[cursor].phoneme).value_or(set.silence());
}
}  // namespace

ScheduleScore scoreSchedule(const PhonemeSchedule& hypothesis, const PhonemeSchedule& reference,
                            const PhonemeSet& set, double step) {
    ScheduleScore score;
    score.confusion.assign(set.size(), std::vector<std::size_t>(set.size(), 0));
    if (reference.empty()) return score;
    const double end = reference.back().end;
    std::size_t refCursor = 0, hypCursor = 0;
    for (double t = step / 2; t < end; t += step) {
        const auto ref = classAt(reference, t, refCursor, set);
        const auto hyp = classAt(hypothesis, t, hypCursor, set);
        ++score.frames;
        score.correct += ref == hyp;
        score.groupCorrect += set[ref].group == set[hyp].group;
        ++score.confusion[ref][hyp];
    }
    return score;
}

}  // namespace lipsyncd::dsp
