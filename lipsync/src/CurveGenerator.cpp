// The generator of the shipped English set: per-class target poses plus coarticulation rules
// (config/curves/english-rules.toml). For the bigram (a, b) and each pose, the control polygon
// holds a's target around a's centre and b's around b's, joined by a line; three equal
// vertices make the B-spline pass through the target, since a cubic B-spline only
// approximates single vertices. The ends sit halfway to rest: max-stitching with the
// neighbouring bigrams supplies the rest of each transition (section 2.2.1).
#include <algorithm>
#include <lipsyncd/lipsync.hpp>
#include <lipsyncd/toml_table.hpp>

namespace lipsyncd::lipsync {

namespace {
struct Rules {
    double firstCentre = 0.25, secondCentre = 0.75, hold = 0.06;
    std::vector<std::vector<float>> targets;  // [class][pose]
    std::vector<std::size_t> closureClasses, releasePoses, leadPoses, roundingPoses;
    std::size_t closurePose = 0;
    float closureValue = 1, leadAmount = 0, anticipation = 0, carryover = 0;
    std::optional<std::size_t> jawPose;  // targets from the phoneme set's jaw heights
    double jawHold = 0;                  // its own plateau half-width
};

std::size_t poseIndex(const TomlTable& t, const std::string& key, const std::string& name,
                      const PoseSet& poses) {
    const auto i = poses.find(name);
    if (!i) t.fail(key, "unknown pose '" + name + "' (pose set '" + poses.name() + "')");
    return *i;
}

std::vector<std::size_t> poseList(const TomlTable& t, const std::string& key,
                                  const PoseSet& poses) {
    std::vector<std::size_t> out;
    for (const auto& n : t.optStringArray(key).value_or(std::vector<std::string>{}))
        out.push_back(poseIndex(t, key, n, poses));
    return out;
}

float fraction(const TomlTable& t, const std::string& key) {
    const double v = t.getNumber(key);
    if (!(v >= 0 && v <= 1)) t.fail(key, "must be in [0, 1]");
    return static_cast<float>(v);
}

// The two plateaus of half-width `hold` around the centres lie inside (0, 1) and apart.
bool plateausFit(const Rules& r, double hold) {
    return hold > 0 && r.firstCentre - hold > 0 && r.firstCentre + hold < r.secondCentre - hold &&
           r.secondCentre + hold < 1;
}

// The jaw pose's target in every class is the class's jaw height (config/phonemes/common.toml),
// the one table the eval reference is built from too.
void readJaw(const TomlTable& root, const PoseSet& poses, const PhonemeSet& phonemes, Rules& r) {
    const auto j = root.optTable("jaw");
    if (!j) return;
    r.jawPose = poseIndex(*j, "pose", j->getString("pose"), poses);
    r.jawHold = fraction(*j, "hold");
    j->finish();
    for (std::size_t c = 0; c < phonemes.size(); ++c) {
        if (!phonemes[c].jaw)
            j->fail("pose", "phoneme class '" + phonemes[c].name + "' has no jaw height");
        r.targets[c][*r.jawPose] = *phonemes[c].jaw;
    }
}

void readTargets(const TomlTable& table, const PoseSet& poses, const PhonemeSet& phonemes,
                 Rules& r) {
    std::vector<bool> seen(phonemes.size(), false);
    for (const auto& cls : table.keys()) {
        const auto c = phonemes.find(cls);
        if (!c) table.fail(cls, "'" + cls + "' is not a phoneme class");
        seen[*c] = true;
        const auto target = table.optTable(cls);
        if (!target) table.fail(cls, "expected a table of pose = weight");
        for (const auto& pose : target->keys()) {
            const auto p = poseIndex(*target, pose, pose, poses);
            if (p == r.jawPose)
                target->fail(pose, "the jaw's targets are the phoneme set's jaw heights");
            r.targets[*c][p] = fraction(*target, pose);
        }
        target->finish();
    }
    for (std::size_t c = 0; c < phonemes.size(); ++c)
        if (!seen[c])
            table.fail("", "no target for class '" + phonemes[c].name + "' (use {} for none)");
}

Rules readRules(const TomlTable& root, const PoseSet& poses, const PhonemeSet& phonemes) {
    Rules r;
    r.firstCentre = fraction(root, "first_centre");
    r.secondCentre = fraction(root, "second_centre");
    r.hold = fraction(root, "hold");
    if (!plateausFit(r, r.hold))
        root.fail("hold", "the two held plateaus must lie inside (0, 1) and apart");
    const auto targets = root.optTable("targets");
    if (!targets) root.fail("targets", "missing [targets]");
    r.targets.assign(phonemes.size(), std::vector<float>(poses.size(), 0.0f));
    readJaw(root, poses, phonemes, r);
    if (r.jawPose && !plateausFit(r, r.jawHold))
        root.fail("jaw", "the jaw's held plateaus must lie inside (0, 1) and apart");
    readTargets(*targets, poses, phonemes, r);
    if (const auto c = root.optTable("closure")) {
        for (const auto& n : c->optStringArray("classes").value_or(std::vector<std::string>{})) {
            const auto i = phonemes.find(n);
            if (!i) c->fail("classes", "'" + n + "' is not a phoneme class");
            r.closureClasses.push_back(*i);
        }
        r.closurePose = poseIndex(*c, "pose", c->getString("pose"), poses);
        r.closureValue = fraction(*c, "value");
        r.releasePoses = poseList(*c, "release", poses);
        c->finish();
    }
    if (const auto j = root.optTable("jaw_lead")) {
        r.leadPoses = poseList(*j, "poses", poses);
        r.leadAmount = fraction(*j, "amount");
        j->finish();
    }
    if (const auto g = root.optTable("rounding")) {
        r.roundingPoses = poseList(*g, "poses", poses);
        r.anticipation = fraction(*g, "anticipation");
        r.carryover = fraction(*g, "carryover");
        g->finish();
    }
    return r;
}

bool contains(const std::vector<std::size_t>& v, std::size_t x) {
    return std::find(v.begin(), v.end(), x) != v.end();
}

// The pose's target in phoneme `c`, with the closure rule applied.
float targetOf(const Rules& r, std::size_t c, std::size_t pose) {
    if (contains(r.closureClasses, c)) {
        if (pose == r.closurePose) return r.closureValue;
        if (contains(r.releasePoses, pose)) return 0;
    }
    return r.targets[c][pose];
}

std::vector<ControlPoint> polygonFor(const Rules& r, const PhonemeSet& set, std::size_t a,
                                     std::size_t b, std::size_t pose) {
    float va = targetOf(r, a, pose), vb = targetOf(r, b, pose);
    const bool aVowel = set[a].vowel, bVowel = set[b].vowel;
    const bool aConsonant = !aVowel && a != set.silence(),
               bConsonant = !bVowel && b != set.silence();
    if (contains(r.roundingPoses, pose)) {
        if (aConsonant && bVowel) va = std::max(va, r.anticipation * vb);
        if (aVowel && bConsonant) vb = std::max(vb, r.carryover * va);
    }
    const double h = pose == r.jawPose ? r.jawHold : r.hold;
    double cb = r.secondCentre;
    if (bVowel && contains(r.leadPoses, pose))
        cb = std::max(r.firstCentre + 2 * h + 0.01, cb - r.leadAmount);
    const auto f = [](double x) { return static_cast<float>(x); };
    const double ca = r.firstCentre;
    return {{0, va / 2},     {f(ca - h), va}, {f(ca), va},     {f(ca + h), va},
            {f(cb - h), vb}, {f(cb), vb},     {f(cb + h), vb}, {1, vb / 2}};
}
}  // namespace

BigramCurveSet generateCurveSet(const std::filesystem::path& rulesFile, const PoseSet& poses,
                                const PhonemeSet& phonemes) {
    const auto root = TomlTable::parseFile(rulesFile);
    const auto poseSet = root.getString("pose_set");
    if (poseSet != poses.name())
        root.fail("pose_set", "rules are for '" + poseSet + "', poses are '" + poses.name() + "'");
    const Rules rules = readRules(root, poses, phonemes);
    BigramCurveSet set(root.getString("name"), poses, phonemes);
    set.description() = root.optString("description").value_or("");
    root.finish();
    for (std::size_t a = 0; a < phonemes.size(); ++a)
        for (std::size_t b = 0; b < phonemes.size(); ++b)
            for (std::size_t p = 0; p < poses.size(); ++p)
                set.setCurve(a, b, p, ControlCurve(polygonFor(rules, phonemes, a, b, p)));
    return set;
}

}  // namespace lipsyncd::lipsync
