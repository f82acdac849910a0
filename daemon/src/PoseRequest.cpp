// `pose`: a client sets the pose weights directly (the curve editor's preview on the puppet).
// The weights go through the puppet driver as a clip's do (gains, limits, slew), so a pose
// request can ask for nothing a clip could not. The table has checked that every value is a
// finite number in [0, 1]; only the daemon knows which poses its curves use.
#include <algorithm>

#include "DaemonCore.hpp"

namespace lipsyncd::daemon {

using nlohmann::json;

namespace {
json refused(const std::string& why) {
    return {{"ok", false}, {"error", "pose: " + why}};
}
}  // namespace

json Daemon::Impl::holdPose(const json& r) {
    // What plays has the mouth: a pose would fight it frame by frame.
    if (const auto* clip = player.clip())
        return refused("refused while a clip plays ('" + clip->name + "'): stop it first");
    if (live) return refused("refused while live input is on: `live off` first");
    const auto& names = setup->clips->poseNames();
    poseWeights.assign(names.size(), 0.0f);  // poses not named: 0
    for (const auto& [name, value] : r["weights"].items()) {
        const auto at = std::find(names.begin(), names.end(), name);
        if (at == names.end()) {
            std::string known;
            for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
            return refused("unknown pose '" + name + "' (this puppet's poses: " + known + ")");
        }
        poseWeights[static_cast<std::size_t>(at - names.begin())] = value.get<float>();
    }
    heldPose.hold(poseWeights, now());
    return {{"ok", true}, {"held", PoseHold::kHoldSeconds}};
}

}  // namespace lipsyncd::daemon
