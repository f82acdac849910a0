// The four-bar linkage between a servo horn and a jaw: servo shaft and jaw hinge are the fixed
// pivots, the horn and the jaw arm the cranks, the pushrod the coupler. For each jaw opening
// the jaw arm's hole is known, and the horn's hole lies where the circle of the horn about the
// shaft meets the circle of the pushrod about the arm's hole (two points: the two ways the
// linkage can be assembled). Solved once at load into a table, so the real-time path only
// interpolates (GLM for the plane geometry).
#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>
#include <lipsyncd/output.hpp>
#include <optional>
#include <sstream>

namespace lipsyncd::output {

namespace {
glm::dvec2 at(const std::array<double, 2>& p) {
    return {p[0], p[1]};
}

glm::dvec2 direction(double degrees) {
    const double r = glm::radians(degrees);
    return {std::cos(r), std::sin(r)};
}

// The horn's direction (degrees) for one assembly branch (+1 / −1), none where the pushrod
// cannot join horn and arm.
std::optional<double> hornDirection(const Linkage& l, double hingeDeg, int branch) {
    const double armDeg = l.armClosedDeg + (l.opensClockwise ? -hingeDeg : hingeDeg);
    const glm::dvec2 shaft = at(l.servo), hole = at(l.hinge) + l.arm * direction(armDeg);
    const glm::dvec2 between = hole - shaft;
    const double d = glm::length(between);
    if (d < 1e-9 || d > l.horn + l.rod || d < std::abs(l.horn - l.rod)) return std::nullopt;
    const double along = (l.horn * l.horn - l.rod * l.rod + d * d) / (2 * d);
    const double across = std::sqrt(std::max(0.0, l.horn * l.horn - along * along));
    const glm::dvec2 unit = between / d, normal{-unit.y, unit.x};
    const glm::dvec2 hornHole = shaft + along * unit + double(branch) * across * normal;
    return glm::degrees(std::atan2(hornHole.y - shaft.y, hornHole.x - shaft.x));
}

// `deg` moved by whole turns into the servo's travel [lo, lo + 360).
double intoTravel(double deg, double lo) {
    return lo + std::fmod(std::fmod(deg - lo, 360.0) + 360.0, 360.0);
}

struct Branch {
    std::vector<LinkageRow> rows;
    std::string whyNot;  // empty: usable over the whole range
};

std::string degrees(double v) {
    std::ostringstream s;
    s << std::round(v * 10) / 10 << "°";
    return s.str();
}

Branch solveBranch(const Linkage& l, double min, double max, std::size_t steps, int branch) {
    const double lo = std::min(l.hornAtPulseMinDeg, l.hornAtPulseMaxDeg);
    const double hi = std::max(l.hornAtPulseMinDeg, l.hornAtPulseMaxDeg);
    Branch b;
    for (std::size_t i = 0; i <= steps; ++i) {
        const double hinge = min + (max - min) * double(i) / double(steps);
        const auto horn = hornDirection(l, hinge, branch);
        if (!horn) {
            b.whyNot = "the pushrod cannot join horn and jaw arm at a jaw opening of " +
                       degrees(hinge) + " (pushrod too short or too long for the pivots)";
            return b;
        }
        const double inTravel = intoTravel(*horn, lo);
        if (inTravel > hi) {
            b.whyNot = "at a jaw opening of " + degrees(hinge) + " the horn must point at " +
                       degrees(*horn) + ", outside the servo's travel " + degrees(lo) + " .. " +
                       degrees(hi);
            return b;
        }
        b.rows.push_back({hinge, inTravel});
    }
    // The jaw must move one way while the horn turns one way: a fold-back (a dead point
    // passed) gives two jaw angles for one horn angle and a servo that cannot hold the jaw.
    for (std::size_t i = 1; i + 1 < b.rows.size(); ++i) {
        const double before = b.rows[i].hornDeg - b.rows[i - 1].hornDeg;
        const double after = b.rows[i + 1].hornDeg - b.rows[i].hornDeg;
        if (before * after <= 0) {
            b.whyNot = "the linkage passes a dead point at a jaw opening of " +
                       degrees(b.rows[i].hingeDeg) + " (the horn turns back there)";
            return b;
        }
    }
    return b;
}
}  // namespace

bool takesServoPulses(Backend backend) {
    return backend == Backend::Servo || backend == Backend::Pca9685 ||
           backend == Backend::Maestro || backend == Backend::Pwm;
}

std::vector<LinkageRow> solveLinkage(const Linkage& l, double min, double max, std::size_t steps) {
    if (!(l.horn > 0 && l.rod > 0 && l.arm > 0))
        throw InputError("horn, rod and arm must be longer than 0 mm");
    const Branch a = solveBranch(l, min, max, steps, +1);
    const Branch b = solveBranch(l, min, max, steps, -1);
    if (!a.whyNot.empty() && !b.whyNot.empty())
        throw InputError("cannot reach " + degrees(min) + " .. " + degrees(max) + ": " +
                         (a.rows.size() >= b.rows.size() ? a.whyNot : b.whyNot));
    if (!a.whyNot.empty()) return b.rows;
    if (!b.whyNot.empty()) return a.rows;
    // Both assemblies work: take the one that keeps the horn nearer the middle of its travel
    // (furthest from the servo's end stops).
    const double middle = (l.hornAtPulseMinDeg + l.hornAtPulseMaxDeg) / 2;
    const auto offCentre = [&](const Branch& x) {
        return std::abs((x.rows.front().hornDeg + x.rows.back().hornDeg) / 2 - middle);
    };
    return offCentre(a) <= offCentre(b) ? a.rows : b.rows;
}

double servoPulseUs(const ActuatorConfig& a, double value) {
    // (The channel never hands on a non-finite value; should one arrive, it means rest.)
    if (!std::isfinite(value)) value = a.rest;
    const double share = std::clamp((value - a.min) / (a.max - a.min), 0.0, 1.0);
    if (!a.linkage || a.linkage->table.size() < 2)
        return a.pulseMinUs + share * (a.pulseMaxUs - a.pulseMinUs);
    const auto& table = a.linkage->table;
    const double at = share * double(table.size() - 1);
    const auto i = std::min(static_cast<std::size_t>(at), table.size() - 2);
    const double horn =
        table[i].hornDeg + (at - double(i)) * (table[i + 1].hornDeg - table[i].hornDeg);
    const auto& l = *a.linkage;
    const double travel =
        (horn - l.hornAtPulseMinDeg) / (l.hornAtPulseMaxDeg - l.hornAtPulseMinDeg);
    return a.pulseMinUs + std::clamp(travel, 0.0, 1.0) * (a.pulseMaxUs - a.pulseMinUs);
}

}  // namespace lipsyncd::output
