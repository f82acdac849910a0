// Every template of a set, laid out for the classifier's distance loop. Σ w·(x−t)² =
// Σ (√w·x − √w·t)²: templates are stored scaled by √w, or multiplied by the set's whitening W
// (‖W(x − t)‖² = ‖Wx − Wt‖²), so a frame is transformed once and compared with every template. Per
// class, its templates go in blocks of eight (the last block padded with copies of the class's last
// template, which cannot change a minimum), each block feature-major ([feature][8 templates]), so
// that one vector operation serves eight templates and no per-template horizontal sum is needed.
//
// A distance is taken as ‖x‖² + ‖t‖² − 2·x·t, each template's norm stored beside its block: a
// multiply and an add per feature and template, and four blocks share each load of the frame's
// feature. Each template's dot product is formed in the same order whatever block it sits in
// (feature f into partial sum f mod 2, the two added last), so the distances do not depend on the
// layout.
//
// A second pass over the same frames on a set where only some templates moved (SpeakerAdaptation)
// need not measure the blocks that did not: the first pass records each block's least distance,
// and the second takes those blocks' from the record (a minimum is the same in any order).
#pragma once

#include <cstddef>
#include <cstdint>
#include <lipsyncd/dsp.hpp>
#include <span>
#include <vector>

namespace lipsyncd::dsp {

// A set's distance as a plain Euclidean one: features scaled by √w (the per-feature weights), or
// multiplied by the set's whitening W (lower triangular), so that ‖T(x) − T(t)‖² is the set's
// distance between a frame x and a template t.
class FeatureWeighting {
  public:
    FeatureWeighting() = default;
    explicit FeatureWeighting(const TemplateSet& templates);
    std::size_t features() const { return features_; }
    // `out` has features() values.
    void transform(std::span<const float> frame, std::span<float> out) const;
    bool operator==(const FeatureWeighting&) const = default;

  private:
    std::size_t features_ = 0;
    std::vector<float> scale_;
    std::vector<float> whitening_;  // [row][column], row-major; empty: diagonal scale_ only
};

class TemplateMatrix {
  public:
    static constexpr std::size_t kLanes = 8;

    TemplateMatrix() = default;
    // Throws InputError for a class the phoneme set does not have.
    TemplateMatrix(const TemplateSet& templates, const PhonemeSet& set);
    std::size_t features() const { return weighting_.features(); }
    // The frame as nearest() takes it (FeatureWeighting). `out` has features() values.
    void transform(std::span<const float> frame, std::span<float> out) const {
        weighting_.transform(frame, out);
    }
    // Squared weighted distance from a scaled frame to the nearest template of each class,
    // indexed by phoneme set index; +inf for classes without templates.
    void nearest(std::span<const float> scaledFrame, std::span<float> out) const;
    // The same, also writing each block's least squared distance to `record` (blocks() values).
    void nearest(std::span<const float> scaledFrame, std::span<float> out,
                 std::span<float> record) const;
    // The same, taking the blocks `same` marks from `record`, made by the matrix `same` was
    // made against (sameBlocks) for the same frame.
    void nearest(std::span<const float> scaledFrame, std::span<float> out,
                 std::span<const std::uint8_t> same, std::span<const float> record) const;
    std::size_t blocks() const { return blockClass_.size(); }
    // Per block: 1 where `other` holds the same templates of the same class, weighed the same,
    // so that its record of a frame holds this matrix's distances for that block.
    std::vector<std::uint8_t> sameBlocks(const TemplateMatrix& other) const;
    // Squared distances (nearest()'s) to the weighted RMS difference in dB, in place.
    void toRms(std::span<float> distances) const;

  private:
    FeatureWeighting weighting_;
    std::vector<float> blocks_;    // [block][feature][lane]
    std::vector<float> norms_;     // [block][lane]: each stored template's ‖t‖²
    std::vector<int> blockClass_;  // phoneme set index of each block (blocks of a class adjacent)
};

}  // namespace lipsyncd::dsp
