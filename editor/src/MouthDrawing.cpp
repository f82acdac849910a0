// How poses move the preview's 2-D mouth: data in config/editor/mouth.toml, so the page knows
// only its own drawing parameters, never the pose names.
#include <algorithm>
#include <array>
#include <lipsyncd/editor.hpp>
#include <lipsyncd/toml_table.hpp>

namespace lipsyncd::editor {

namespace {
// What editor.js draws; keep the two in step.
constexpr std::array<const char*, 8> kParameters{"jaw",  "width",     "round",       "press",
                                                 "bite", "tongue_up", "tongue_down", "tongue_back"};

std::vector<double> readAmounts(const TomlTable& table) {
    std::vector<double> out(kParameters.size(), 0.0);
    for (const auto& key : table.keys()) {
        const auto* it = std::find(kParameters.begin(), kParameters.end(), key);
        if (it == kParameters.end())
            table.fail(key,
                       "not a drawing parameter (jaw, width, round, press, bite, "
                       "tongue_up, tongue_down, tongue_back)");
        const double v = table.getNumber(key);
        if (!(v >= -1 && v <= 1)) table.fail(key, "must be in [-1, 1]");
        out[static_cast<std::size_t>(it - kParameters.begin())] = v;
    }
    table.finish();
    return out;
}
}  // namespace

MouthDrawing MouthDrawing::load(const std::filesystem::path& file,
                                const lipsync::PoseSet& poseSet) {
    const auto doc = TomlTable::parseFile(file);
    MouthDrawing m;
    m.parameters.assign(kParameters.begin(), kParameters.end());
    const auto neutral = doc.optTable("neutral");
    m.neutral = neutral ? readAmounts(*neutral) : std::vector<double>(kParameters.size(), 0.0);
    if (const auto poses = doc.optTable("pose")) {
        for (const auto& name : poses->keys()) {
            const auto table = poses->optTable(name);
            if (!table) poses->fail(name, "expected a table [pose." + name + "]");
            auto amounts = readAmounts(*table);
            if (poseSet.find(name)) m.poses.emplace_back(name, std::move(amounts));
        }
        poses->finish();
    }
    doc.finish();
    return m;
}

}  // namespace lipsyncd::editor
