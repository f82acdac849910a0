// Pose sets as data (config/poses/*.toml), read strictly: unknown keys, unknown poses, repeated
// names and out-of-range numbers stop loading with the file and line.
#include <algorithm>
#include <lipsyncd/lipsync.hpp>
#include <lipsyncd/toml_table.hpp>

namespace lipsyncd::lipsync {

PoseSet::PoseSet(std::string name, std::vector<Pose> poses, std::vector<PoseConstraint> constraints,
                 RestRule rest)
    : name_(std::move(name)),
      poses_(std::move(poses)),
      constraints_(std::move(constraints)),
      rest_(rest) {
    // Section 2.2.2 resolves each constraint by priority; applying the ones whose winning pose
    // ranks highest first means a pose is final before it limits anything lower.
    std::stable_sort(constraints_.begin(), constraints_.end(), [&](const auto& a, const auto& b) {
        return poses_[a.high].priority > poses_[b.high].priority;
    });
}

std::vector<std::string> PoseSet::names() const {
    std::vector<std::string> out;
    for (const auto& p : poses_) out.push_back(p.name);
    return out;
}

std::optional<std::size_t> PoseSet::find(const std::string& name) const {
    for (std::size_t i = 0; i < poses_.size(); ++i)
        if (poses_[i].name == name) return i;
    return std::nullopt;
}

namespace {
double positive(const TomlTable& t, const std::string& key, double fallback) {
    const double v = t.optNumber(key).value_or(fallback);
    if (!(v > 0)) t.fail(key, "must be greater than 0");
    return v;
}

std::vector<PoseConstraint> readConstraints(const TomlTable& root, const std::vector<Pose>& poses) {
    std::vector<PoseConstraint> out;
    for (const auto& c : root.tableArray("constraint")) {
        const auto names = c.optStringArray("poses");
        if (!names || names->size() != 2) c.fail("poses", "must name exactly two poses");
        std::size_t idx[2];
        for (int i = 0; i < 2; ++i) {
            auto it = std::find_if(poses.begin(), poses.end(),
                                   [&](const Pose& p) { return p.name == (*names)[i]; });
            if (it == poses.end()) c.fail("poses", "unknown pose '" + (*names)[i] + "'");
            idx[i] = static_cast<std::size_t>(it - poses.begin());
        }
        if (idx[0] == idx[1]) c.fail("poses", "a pose cannot constrain itself");
        if (poses[idx[0]].priority == poses[idx[1]].priority)
            c.fail("poses", "'" + poses[idx[0]].name + "' and '" + poses[idx[1]].name +
                                "' have the same priority: which one gives way?");
        PoseConstraint pc;
        pc.high = poses[idx[0]].priority > poses[idx[1]].priority ? idx[0] : idx[1];
        pc.low = pc.high == idx[0] ? idx[1] : idx[0];
        pc.threshold = c.getNumber("threshold");
        if (!(pc.threshold >= 0 && pc.threshold <= 2)) c.fail("threshold", "must be in [0, 2]");
        c.finish();
        out.push_back(pc);
    }
    return out;
}
RestRule readRest(const TomlTable& root) {
    RestRule rest;
    if (const auto t = root.optTable("rest")) {
        rest.minPause = t->optNumber("min_pause").value_or(rest.minPause);
        if (!(rest.minPause >= 0 && rest.minPause <= 10))
            t->fail("min_pause", "must be in [0, 10] s");
        rest.within = positive(*t, "within", rest.within);
        if (rest.within > 1) t->fail("within", "must be at most 1 s");
        t->finish();
    }
    return rest;
}
}  // namespace

PoseSet PoseSet::load(const std::filesystem::path& file) {
    const auto root = TomlTable::parseFile(file);
    const auto name = root.getString("name");
    root.optString("description");
    const double speed = positive(root, "speed_limit", 6.0);
    const double window = positive(root, "smoothing_window", 0.18);
    std::vector<Pose> poses;
    for (const auto& t : root.tableArray("pose")) {
        Pose p;
        p.name = t.getString("name");
        if (std::any_of(poses.begin(), poses.end(),
                        [&](const Pose& q) { return q.name == p.name; }))
            t.fail("name", "pose '" + p.name + "' is defined twice");
        p.priority = static_cast<int>(t.optInteger("priority").value_or(0));
        p.speedLimit = positive(t, "speed_limit", speed);
        p.smoothingWindow = positive(t, "smoothing_window", window);
        p.loudnessGain = t.optNumber("loudness_gain").value_or(0);
        if (!(p.loudnessGain >= 0 && p.loudnessGain <= 1))
            t.fail("loudness_gain", "must be in [0, 1]");
        p.heardJaw = t.optNumber("heard_jaw").value_or(0);
        if (!(p.heardJaw >= 0 && p.heardJaw <= 1)) t.fail("heard_jaw", "must be in [0, 1]");
        p.heardJawAligned = t.optNumber("heard_jaw_aligned").value_or(0);
        if (!(p.heardJawAligned >= 0 && p.heardJawAligned <= 1))
            t.fail("heard_jaw_aligned", "must be in [0, 1]");
        p.heardJawClosedBy = t.optString("heard_jaw_closed_by").value_or("");
        if (const auto doubt = t.optNumberArray("heard_jaw_doubts_closure")) {
            const auto& d = *doubt;
            if (d.size() != 2 || !(d[0] >= 0 && d[0] < d[1] && d[1] <= 1))
                t.fail("heard_jaw_doubts_closure", "must be [from, to] with 0 <= from < to <= 1");
            p.closureHeldBelow = d[0];
            p.closureDoubtedAbove = d[1];
        }
        p.dipDepth = t.optNumber("dip_depth").value_or(0);
        if (!(p.dipDepth >= 0 && p.dipDepth <= 1)) t.fail("dip_depth", "must be in [0, 1]");
        p.dipRise = t.optNumber("dip_rise").value_or(p.dipRise);
        if (!(p.dipRise > 0 && p.dipRise <= 1)) t.fail("dip_rise", "must be in (0, 1]");
        t.finish();
        poses.push_back(std::move(p));
    }
    if (poses.empty()) throw InputError(file.string(), 0, "no [[pose]] defined");
    for (const auto& p : poses)
        if (!p.heardJawClosedBy.empty() &&
            std::none_of(poses.begin(), poses.end(),
                         [&](const Pose& q) { return q.name == p.heardJawClosedBy; }))
            throw InputError(file.string(), 0,
                             "pose '" + p.name + "': heard_jaw_closed_by: no pose named '" +
                                 p.heardJawClosedBy + "'");
    auto constraints = readConstraints(root, poses);
    const auto rest = readRest(root);
    root.finish();
    return PoseSet(name, std::move(poses), std::move(constraints), rest);
}

PoseSet PoseSet::named(const std::string& nameOrPath) {
    return load(findNamedDataFile(nameOrPath, "poses", ".toml"));
}

}  // namespace lipsyncd::lipsync
