// Levinson–Durbin recursion for the autocorrelation method of linear prediction (Lewis,
// section "Linear prediction speech model": the Toeplitz normal equations; Makhoul 1975,
// eqs. 38a–38e; Rabiner & Schafer 1978, 8.3.2).
//
// Convention: A(z) = 1 + Σ a[i] z^-i is the inverse (whitening) filter, so the predictor is
// x̂[n] = −Σ a[i] x[n−i]. k[i] is the reflection coefficient of step i in the same sign
// convention (k[i] = a_i^(i)); the PARCOR coefficients of some texts are −k.
#include <cmath>
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {

LpcResult levinsonDurbin(std::span<const float> r, int order) {
    LpcResult out;
    out.a[0] = 1.0f;
    order = std::min({order, kMaxOrder, static_cast<int>(r.size()) - 1});
    // Double precision inside: the recursion loses digits at order 12+ on peaky spectra.
    std::array<double, kMaxOrder + 1> a{};
    a[0] = 1.0;
    double error = r.empty() ? 0.0 : r[0];
    if (!(error > 0) || !std::isfinite(error)) {
        out.stable = false;
        out.predictionError = 0;
        out.normalizedError = 1;
        return out;
    }
    std::array<double, kMaxOrder + 1> rd{};  // r in double once, not in every product
    for (int i = 0; i <= order; ++i) rd[i] = r[i];
    for (int i = 1; i <= order; ++i) {
        double acc = rd[i];
        for (int j = 1; j < i; ++j) acc += a[j] * rd[i - j];
        const double k = -acc / error;
        if (!(std::abs(k) < 1.0)) {  // also catches NaN: the frame is degenerate
            out.stable = false;
            break;
        }
        // a_j ← a_j + k·a_(i−j) for j < i, in place: update the pair (j, i−j) together.
        for (int j = 1, m = i - 1; j <= m; ++j, --m) {
            const double aj = a[j], am = a[m];
            a[j] = aj + k * am;
            if (j != m) a[m] = am + k * aj;
        }
        a[i] = k;
        out.k[i - 1] = static_cast<float>(k);
        error *= 1.0 - k * k;
        out.order = i;
    }
    for (int i = 0; i <= out.order; ++i) out.a[i] = static_cast<float>(a[i]);
    out.predictionError = static_cast<float>(error);
    out.normalizedError = static_cast<float>(error / r[0]);
    return out;
}

}  // namespace lipsyncd::dsp
