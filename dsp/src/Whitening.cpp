// Mahalanobis whitening by Cholesky factorisation (Golub & Van Loan 2013, §4.2): Σ = L Lᵀ, then
// L⁻¹ by forward substitution. L⁻¹ stays lower triangular, so a frame's transform costs n²/2.
#include "Whitening.hpp"

#include <cmath>
#include <lipsyncd/core.hpp>
#include <string>

namespace lipsyncd::dsp {

namespace {
std::vector<double> cholesky(std::span<const double> a, std::size_t n) {
    std::vector<double> l(n * n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j <= i; ++j) {
            double sum = a[i * n + j];
            for (std::size_t k = 0; k < j; ++k) sum -= l[i * n + k] * l[j * n + k];
            if (i == j) {
                if (!(sum > 0))
                    throw InputError(
                        "whitening: the covariance is not positive definite (feature " +
                        std::to_string(i) + ")");
                l[i * n + i] = std::sqrt(sum);
            } else {
                l[i * n + j] = sum / l[j * n + j];
            }
        }
    return l;
}

// Inverse of a lower-triangular matrix, column by column (L x = e_j).
std::vector<double> invertLower(const std::vector<double>& l, std::size_t n) {
    std::vector<double> inv(n * n, 0.0);
    for (std::size_t j = 0; j < n; ++j)
        for (std::size_t i = j; i < n; ++i) {
            double sum = i == j ? 1.0 : 0.0;
            for (std::size_t k = j; k < i; ++k) sum -= l[i * n + k] * inv[k * n + j];
            inv[i * n + j] = sum / l[i * n + i];
        }
    return inv;
}
}  // namespace

std::vector<std::vector<float>> whiteningFromCovariance(std::span<const double> covariance,
                                                        std::size_t n, double s) {
    const auto inv = invertLower(cholesky(covariance, n), n);
    std::vector<std::vector<float>> w(n, std::vector<float>(n, 0.0f));
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j <= i; ++j) w[i][j] = static_cast<float>(s * inv[i * n + j]);
    return w;
}

}  // namespace lipsyncd::dsp
