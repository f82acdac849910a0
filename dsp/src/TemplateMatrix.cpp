#include "TemplateMatrix.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "VectorLanes.hpp"

namespace lipsyncd::dsp {

namespace {
// ‖x‖², its terms summed in order.
float squaredNorm(std::span<const float> x) {
    float sum = 0;
    for (const float v : x) sum += v * v;
    return sum;
}
}  // namespace

FeatureWeighting::FeatureWeighting(const TemplateSet& templates)
    : features_(templates.binWeights.size()) {
    scale_.resize(features_);
    for (std::size_t b = 0; b < features_; ++b) scale_[b] = std::sqrt(templates.binWeights[b]);
    for (const auto& row : templates.whitening)
        whitening_.insert(whitening_.end(), row.begin(), row.end());
}

void FeatureWeighting::transform(std::span<const float> frame, std::span<float> out) const {
    if (whitening_.empty()) {
        for (std::size_t b = 0; b < features_; ++b) out[b] = frame[b] * scale_[b];
        return;
    }
    for (std::size_t r = 0; r < features_; ++r) {  // lower triangular: columns 0..r
        const float* row = whitening_.data() + r * features_;
        float sum = 0;
        for (std::size_t c = 0; c <= r; ++c) sum += row[c] * frame[c];
        out[r] = sum;
    }
}

TemplateMatrix::TemplateMatrix(const TemplateSet& templates, const PhonemeSet& set)
    : weighting_(templates) {
    const std::size_t features = weighting_.features();
    std::vector<float> stored(features);
    for (const auto& c : templates.classes) {
        const auto idx = set.find(c.phoneme);
        if (!idx)
            throw InputError("templates: class '" + c.phoneme + "' is not in the phoneme set");
        for (std::size_t first = 0; first < c.spectra.size(); first += kLanes) {
            const std::size_t at = blocks_.size();
            blocks_.resize(at + features * kLanes);
            for (std::size_t lane = 0; lane < kLanes; ++lane) {
                transform(c.spectra[std::min(first + lane, c.spectra.size() - 1)], stored);
                for (std::size_t b = 0; b < features; ++b)
                    blocks_[at + b * kLanes + lane] = stored[b];
                norms_.push_back(squaredNorm(stored));
            }
            blockClass_.push_back(static_cast<int>(*idx));
        }
    }
}

namespace {
// Eight templates at once, one per lane.
using Lanes = FloatLanes;
static_assert(TemplateMatrix::kLanes == kVectorLanes, "a block is one vector of lanes");

// Beside the distances: each block's least distance recorded, or some blocks' taken as known.
struct BlockRecord {
    float* write = nullptr;               // per block, or null
    const std::uint8_t* known = nullptr;  // per block: 1 where `values` holds it, or null
    const float* values = nullptr;
};

// The least of the lanes that are numbers, as the running minimum below keeps them.
float leastLane(const Lanes& v) {
    float m = std::numeric_limits<float>::infinity();
    for (std::size_t lane = 0; lane < TemplateMatrix::kLanes; ++lane) m = v[lane] < m ? v[lane] : m;
    return m;
}

// Squared distances from x to the templates of N adjacent blocks, as ‖x‖² + (‖t‖² − 2·x·t): a
// multiply and an add per feature and template, where (x − t)² took a subtract as well. The loop
// is bound by its loads, so N blocks share each broadcast of x[f] (N = 4: 5 loads per 4 block
// features, not 8). Each template's dot product is formed the same way for any N: feature f into
// partial sum f mod 2, the two added last. The norms are a few thousand and the distances that
// decide a class a few hundred, so the rounding this adds is about 1e-3 of a squared dB.
template <std::size_t N>
[[gnu::always_inline]] inline void blockDistances(const float* x, float xNorm, std::size_t features,
                                                  const float* t, const float* norms, Lanes* sums) {
    constexpr std::size_t kStride = TemplateMatrix::kLanes;
    const std::size_t blockStride = features * kStride;
    Lanes even[N] = {}, odd[N] = {};
    auto add = [&](Lanes* acc, std::size_t f) {
        const float xf = x[f];
#pragma GCC unroll 4
        for (std::size_t b = 0; b < N; ++b) {
            Lanes row;
            std::memcpy(&row, t + b * blockStride + f * kStride, sizeof row);
            acc[b] += xf * row;
        }
    };
    std::size_t f = 0;
    for (; f + 1 < features; f += 2) {
        add(even, f);
        add(odd, f + 1);
    }
    if (f < features) add(even, f);
#pragma GCC unroll 4
    for (std::size_t b = 0; b < N; ++b) {
        Lanes norm;
        std::memcpy(&norm, norms + b * kStride, sizeof norm);
        const Lanes dot = even[b] + odd[b];
        sums[b] = (norm - (dot + dot)) + xNorm;
    }
}

// The running minimum of each class over its blocks (a class's blocks are adjacent), taken into
// `out` (which starts at +inf) when the next class starts.
class ClassMinimum {
  public:
    explicit ClassMinimum(float* out) : out_(out) {}
    void add(int cls, const Lanes& sums) {
        start(cls);
        best_ = sums < best_ ? sums : best_;
    }
    void addKnown(int cls, float least) {
        start(cls);
        known_ = std::min(known_, least);
    }
    void finish() {
        if (cls_ < 0) return;
        // Rounding can take a distance of (almost) zero just below it.
        const float least = std::max(0.0f, std::min(leastLane(best_), known_));
        out_[cls_] = std::min(out_[cls_], least);
    }

  private:
    void start(int cls) {
        if (cls == cls_) return;
        finish();
        cls_ = cls;
        for (std::size_t lane = 0; lane < TemplateMatrix::kLanes; ++lane)
            best_[lane] = std::numeric_limits<float>::infinity();
        known_ = std::numeric_limits<float>::infinity();
    }
    float* out_;
    int cls_ = -1;
    Lanes best_{};
    float known_ = 0;
};

LIPSYNCD_VECTOR_CLONES void nearestPerClass(const float* x, float xNorm, std::size_t features,
                                            const float* blocks, const float* norms,
                                            const int* blockClass, std::size_t blockCount,
                                            BlockRecord record, float* out) {
    constexpr std::size_t kGroup = 4;
    const std::size_t stride = features * TemplateMatrix::kLanes;
    auto known = [&](std::size_t block) { return record.known && record.known[block]; };
    ClassMinimum minimum(out);
    for (std::size_t block = 0; block < blockCount;) {
        if (known(block)) {
            minimum.addKnown(blockClass[block], record.values[block]);
            ++block;
            continue;
        }
        std::size_t n = 1;
        if (block + kGroup <= blockCount && !known(block + 1) && !known(block + 2) &&
            !known(block + 3))
            n = kGroup;
        Lanes sums[kGroup];
        const float* t = blocks + block * stride;
        const float* norm = norms + block * TemplateMatrix::kLanes;
        if (n == kGroup)
            blockDistances<kGroup>(x, xNorm, features, t, norm, sums);
        else
            blockDistances<1>(x, xNorm, features, t, norm, sums);
        for (std::size_t i = 0; i < n; ++i, ++block) {
            if (record.write) record.write[block] = leastLane(sums[i]);
            minimum.add(blockClass[block], sums[i]);
        }
    }
    minimum.finish();
}
}  // namespace

void TemplateMatrix::nearest(std::span<const float> scaledFrame, std::span<float> out) const {
    std::fill(out.begin(), out.end(), std::numeric_limits<float>::infinity());
    nearestPerClass(scaledFrame.data(), squaredNorm(scaledFrame), features(), blocks_.data(),
                    norms_.data(), blockClass_.data(), blockClass_.size(), {}, out.data());
}

void TemplateMatrix::nearest(std::span<const float> scaledFrame, std::span<float> out,
                             std::span<float> record) const {
    std::fill(out.begin(), out.end(), std::numeric_limits<float>::infinity());
    nearestPerClass(scaledFrame.data(), squaredNorm(scaledFrame), features(), blocks_.data(),
                    norms_.data(), blockClass_.data(), blockClass_.size(), {record.data()},
                    out.data());
}

void TemplateMatrix::nearest(std::span<const float> scaledFrame, std::span<float> out,
                             std::span<const std::uint8_t> same,
                             std::span<const float> record) const {
    std::fill(out.begin(), out.end(), std::numeric_limits<float>::infinity());
    nearestPerClass(scaledFrame.data(), squaredNorm(scaledFrame), features(), blocks_.data(),
                    norms_.data(), blockClass_.data(), blockClass_.size(),
                    {nullptr, same.data(), record.data()}, out.data());
}

std::vector<std::uint8_t> TemplateMatrix::sameBlocks(const TemplateMatrix& other) const {
    std::vector<std::uint8_t> same(blocks(), 0);
    if (!(weighting_ == other.weighting_) || blockClass_ != other.blockClass_) return same;
    const std::size_t stride = features() * kLanes;
    for (std::size_t b = 0; b < blocks(); ++b)
        same[b] = std::memcmp(&blocks_[b * stride], &other.blocks_[b * stride],
                              stride * sizeof(float)) == 0;
    return same;
}

void TemplateMatrix::toRms(std::span<float> distances) const {
    const auto n = static_cast<float>(features());
    for (auto& d : distances)
        if (std::isfinite(d)) d = std::sqrt(d / n);
}

}  // namespace lipsyncd::dsp
