// Reading and writing phoneme schedules as text (TSV and .lab; DESIGN.md "File formats").
#include <lipsyncd/core.hpp>

#include <nlohmann/json.hpp>

#include <charconv>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace lipsyncd {

namespace {

// Two segments closer than this (seconds) count as touching: labels are written in ms.
constexpr double kTimeTolerance = 1e-4;
// The longest schedule read (a day): beyond it a time is a typo or an attack, and every
// consumer that steps through time (animate, drive) would run for ever or exhaust memory.
constexpr double kMaxSeconds = 86400;

std::vector<std::string_view> splitFields(std::string_view line) {
    std::vector<std::string_view> fields;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
        const std::size_t start = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
        if (i > start) fields.push_back(line.substr(start, i - start));
    }
    return fields;
}

double parseTime(std::string_view text, const std::string& source, std::size_t line,
                 const char* column) {
    double value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
        throw InputError(source, line,
                         std::string(column) + " time '" + std::string(text) + "' is not a number");
    if (value < 0)
        throw InputError(source, line, std::string(column) + " time " + std::string(text) +
                                           " is negative");
    if (value > kMaxSeconds)
        throw InputError(source, line, std::string(column) + " time " + std::string(text) +
                                           " is beyond 86400 s (a day)");
    return value;
}

struct SymbolResolver {
    const ScheduleReadOptions& options;
    const PhonemeSet& set;
    const std::string& source;
    std::vector<std::string>* warnings;

    void warn(std::size_t line, const std::string& what) const {
        if (warnings) warnings->push_back(source + ":" + std::to_string(line) + ": " + what);
    }

    // The class name for a symbol, or nullopt when the symbol is not a sound (ignored mark).
    std::optional<std::string> resolve(std::string_view symbol, std::size_t line) const {
        if (options.map) {
            if (options.map->isIgnored(symbol)) return std::nullopt;
            if (auto r = options.map->map(symbol)) {
                if (r->approximate)
                    warn(line, "phoneme '" + std::string(symbol) + "' approximated as '" +
                                   r->phoneme + "' (map " + options.map->name() + ")");
                return r->phoneme;
            }
        } else if (set.find(symbol)) {
            return std::string(symbol);
        }
        const std::string what = "unknown phoneme '" + std::string(symbol) + "'" +
                                 (options.map ? " (not in map " + options.map->name() + ")"
                                              : " (not a class of the phoneme set)");
        if (options.unknownIsError) throw InputError(source, line, what);
        warn(line, what + "; treated as silence");
        return set[set.silence()].name;
    }
};

}  // namespace

PhonemeSchedule readSchedule(std::istream& in, const std::string& sourceName,
                             const ScheduleReadOptions& options,
                             std::vector<std::string>* warnings) {
    const PhonemeSet& set = options.set ? *options.set : PhonemeSet::common();
    const SymbolResolver resolver{options, set, sourceName, warnings};
    const std::string silence = set[set.silence()].name;
    PhonemeSchedule out;
    std::string text;
    std::size_t lineNo = 0;
    while (std::getline(in, text)) {
        ++lineNo;
        const auto hash = text.find('#');
        const auto fields = splitFields(std::string_view(text).substr(0, hash));
        if (fields.empty()) continue;
        if (fields.size() < 3 || fields.size() > 4)
            throw InputError(sourceName, lineNo,
                             "expected 'start end phoneme [confidence]', found " +
                                 std::to_string(fields.size()) + " fields");
        PhonemeSegment seg;
        seg.start = parseTime(fields[0], sourceName, lineNo, "start");
        seg.end = parseTime(fields[1], sourceName, lineNo, "end");
        if (seg.end <= seg.start)
            throw InputError(sourceName, lineNo, "segment ends (" + std::string(fields[1]) +
                                                     ") before it starts (" +
                                                     std::string(fields[0]) + ")");
        if (fields.size() == 4) {
            const double c = parseTime(fields[3], sourceName, lineNo, "confidence");
            if (c > 1) throw InputError(sourceName, lineNo, "confidence above 1");
            seg.confidence = static_cast<float>(c);
        }
        auto phoneme = resolver.resolve(fields[2], lineNo);
        if (!phoneme) continue;
        seg.phoneme = std::move(*phoneme);
        const double previousEnd = out.empty() ? 0.0 : out.back().end;
        if (seg.start < previousEnd - kTimeTolerance)
            throw InputError(sourceName, lineNo,
                             out.empty() ? "segment starts before 0"
                                         : "segment overlaps or is out of order with the one "
                                           "before (it ends at " +
                                               std::to_string(previousEnd) + ")");
        if (seg.start > previousEnd + kTimeTolerance) {
            if (!options.fillGapsWithSilence && !out.empty())
                throw InputError(sourceName, lineNo, "gap before this segment (previous ends at " +
                                                         std::to_string(previousEnd) + ")");
            out.push_back({previousEnd, seg.start, silence, 1.0f});
        } else {
            seg.start = previousEnd > 0 ? previousEnd : seg.start;
        }
        // Neighbouring segments of one class are one segment.
        if (!out.empty() && out.back().phoneme == seg.phoneme) {
            out.back().end = seg.end;
            out.back().confidence = std::min(out.back().confidence, seg.confidence);
        } else {
            out.push_back(std::move(seg));
        }
    }
    return out;
}

PhonemeSchedule readScheduleFile(const std::filesystem::path& file,
                                 const ScheduleReadOptions& options,
                                 std::vector<std::string>* warnings) {
    if (file == "-") return readSchedule(std::cin, "<stdin>", options, warnings);
    std::ifstream in(file);
    if (!in) throw InputError(file.string() + ": cannot open");
    return readSchedule(in, file.string(), options, warnings);
}

namespace {

// The segments as written: times in whole milliseconds, and a segment that rounds to no length
// (a sliver at a file's end, e.g. 0.9978 to 0.998 s) left out, so that its neighbours still
// touch and every file written reads back (the reader refuses a segment that ends where it
// starts).
std::vector<PhonemeSegment> asWritten(std::span<const PhonemeSegment> schedule) {
    std::vector<PhonemeSegment> out;
    out.reserve(schedule.size());
    for (const auto& s : schedule) {
        const double start = std::round(s.start * 1000) / 1000;
        const double end = std::round(s.end * 1000) / 1000;
        if (end <= start) continue;
        out.push_back({start, end, s.phoneme, s.confidence});
    }
    return out;
}

}  // namespace

void writeSchedule(std::ostream& out, std::span<const PhonemeSegment> schedule,
                   bool withConfidence) {
    out << std::fixed;
    for (const auto& s : asWritten(schedule)) {
        out << std::setprecision(3) << s.start << '\t' << s.end << '\t' << s.phoneme;
        if (withConfidence) out << '\t' << std::setprecision(2) << s.confidence;
        out << '\n';
    }
}

void writeScheduleJson(std::ostream& out, std::span<const PhonemeSegment> schedule) {
    auto arr = nlohmann::json::array();
    for (const auto& s : asWritten(schedule))
        arr.push_back({{"start", s.start},
                       {"end", s.end},
                       {"phoneme", s.phoneme},
                       {"confidence", std::round(s.confidence * 100) / 100}});
    out << arr.dump(1) << '\n';
}

}  // namespace lipsyncd
