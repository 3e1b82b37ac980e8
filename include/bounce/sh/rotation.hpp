#pragma once
/// \file sh/rotation.hpp
/// Rotating SH coefficients by a 3x3 rotation, exactly (to rounding) for any number of
/// bands: each band l has a (2l + 1) x (2l + 1) matrix built from band l - 1 and band 1 by
/// the recurrence of Ivanic and Ruedenberg ("Rotation Matrices for Real Spherical Harmonics.
/// Direct Determination by Recursion", J. Phys. Chem. 100(15), 1996, Eqs. 8.1-8.7 and
/// Tables 1-2, with the 1998 erratum: the V term for m < 0 is
/// P(1, m + 1) (1 - delta_m,-1) + P(-1, -m - 1) sqrt(1 + delta_m,-1)).
///
/// Their real harmonics have no Condon-Shortley phase; ours (sh/basis.hpp) have it, which
/// flips the sign of odd m: the band matrices here are theirs conjugated by
/// diag((-1)^m). Band 1 seeds the recurrence with the rotation itself, in the order
/// (y, z, x) of Y_1,-1, Y_10, Y_11.
///
/// Meaning: for a function f with coefficients c, `apply(c)` gives the coefficients of the
/// rotated function g(R d) = f(d), i.e. g(d) = f(R^T d): a light coming from direction a
/// comes from R a afterwards (tests/sh checks this against re-projection).

#include <bounce/errors.hpp>
#include <bounce/sh/basis.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

namespace bounce::inline sh {

/// The rotation matrices of bands 0 .. L - 1 for one 3x3 rotation.
template <int L>
class sh_rotation {
public:
    /// The band matrices of the rotation `r` (GLM, column-major: r[column][row]; it maps a
    /// direction d to r * d). Throws parameter_error naming "r" unless r is orthonormal with
    /// determinant +1 to within 1e-6 (a reflection is not a rotation of the sphere's
    /// functions in this basis without flipping odd bands).
    explicit sh_rotation(const glm::dmat3& r) {
        static_assert(L >= 1, "sh_rotation: at least one band");
        const glm::dmat3 should_be_identity = glm::transpose(r) * r;
        double off = 0;
        for (int c = 0; c < 3; ++c)
            for (int k = 0; k < 3; ++k) off = std::max(off, std::abs(should_be_identity[c][k] - (c == k ? 1.0 : 0.0)));
        require(off < 1e-6 && std::abs(glm::determinant(r) - 1) < 1e-6, "r", "not a rotation (orthonormal, det +1)");
        for (int l = 0; l < L; ++l) offsets_[std::size_t(l)] = l == 0 ? 0 : offsets_[std::size_t(l - 1)] + std::size_t((2 * l - 1) * (2 * l - 1));
        m_.assign(offsets_[std::size_t(L - 1)] + std::size_t((2 * L - 1) * (2 * L - 1)), 0.0);
        at(0, 0, 0) = 1;
        if (L == 1) return;
        // Band 1 in (y, z, x) order, m = -1, 0, 1 (Ivanic and Ruedenberg, Eq. 7.2).
        const int axis[3] = {1, 2, 0};
        for (int m = -1; m <= 1; ++m)
            for (int n = -1; n <= 1; ++n) at(1, m, n) = r[axis[n + 1]][axis[m + 1]];
        for (int l = 2; l < L; ++l) build_band(l);
        // Into the Condon-Shortley phase convention: (-1)^(m + n).
        for (int l = 1; l < L; ++l)
            for (int m = -l; m <= l; ++m)
                for (int n = -l; n <= l; ++n)
                    if ((m + n) % 2 != 0) at(l, m, n) = -at(l, m, n);
    }

    /// Element (m, n) of band l's matrix: coefficient m of the rotated function takes
    /// element(l, m, n) times coefficient n of the original.
    double element(int l, int m, int n) const { return m_[offsets_[std::size_t(l)] + std::size_t((m + l) * (2 * l + 1) + n + l)]; }

    /// The coefficients of the rotated function (see the file comment). `C` is double,
    /// glm::dvec3 or glm::vec3.
    template <class C>
    sh_coefficients<L, C> apply(const sh_coefficients<L, C>& c) const {
        sh_coefficients<L, C> out{};
        for (int l = 0; l < L; ++l)
            for (int m = -l; m <= l; ++m) {
                C sum = c[sh_index(l, -l)] * element(l, m, -l);
                for (int n = -l + 1; n <= l; ++n) sum = sum + c[sh_index(l, n)] * element(l, m, n);
                out[sh_index(l, m)] = sum;
            }
        return out;
    }

private:
    double& at(int l, int m, int n) { return m_[offsets_[std::size_t(l)] + std::size_t((m + l) * (2 * l + 1) + n + l)]; }
    double phase_free(int l, int m, int n) const { return element(l, m, n); }

    // Ivanic and Ruedenberg, Table 2: P, U, V, W of band l from band l - 1 (no phase yet).
    double p_term(int i, int a, int b, int l) const {
        const double r1 = phase_free(1, i, 1), r0 = phase_free(1, i, 0), rm = phase_free(1, i, -1);
        if (b == l) return r1 * phase_free(l - 1, a, l - 1) - rm * phase_free(l - 1, a, -l + 1);
        if (b == -l) return r1 * phase_free(l - 1, a, -l + 1) + rm * phase_free(l - 1, a, l - 1);
        return r0 * phase_free(l - 1, a, b);
    }
    double u_term(int m, int n, int l) const { return p_term(0, m, n, l); }
    double v_term(int m, int n, int l) const {
        if (m == 0) return p_term(1, 1, n, l) + p_term(-1, -1, n, l);
        if (m > 0) {
            const double d = m == 1 ? 1.0 : 0.0;
            return p_term(1, m - 1, n, l) * std::sqrt(1 + d) - p_term(-1, -m + 1, n, l) * (1 - d);
        }
        const double d = m == -1 ? 1.0 : 0.0;
        return p_term(1, m + 1, n, l) * (1 - d) + p_term(-1, -m - 1, n, l) * std::sqrt(1 + d);
    }
    double w_term(int m, int n, int l) const {
        if (m > 0) return p_term(1, m + 1, n, l) + p_term(-1, -m - 1, n, l);
        return p_term(1, m - 1, n, l) - p_term(-1, -m + 1, n, l);
    }

    // Ivanic and Ruedenberg, Table 1 (u, v, w) and Eq. 8.1.
    void build_band(int l) {
        for (int m = -l; m <= l; ++m)
            for (int n = -l; n <= l; ++n) {
                const double d = m == 0 ? 1.0 : 0.0;
                const int am = m < 0 ? -m : m;
                const double denominator = (n == l || n == -l) ? double(2 * l) * double(2 * l - 1) : double(l + n) * double(l - n);
                const double u = std::sqrt(double(l + m) * double(l - m) / denominator);
                const double v = 0.5 * std::sqrt((1 + d) * double(l + am - 1) * double(l + am) / denominator) * (1 - 2 * d);
                const double w = -0.5 * std::sqrt(double(l - am - 1) * double(l - am) / denominator) * (1 - d);
                double value = 0;
                if (u != 0) value += u * u_term(m, n, l);
                if (v != 0) value += v * v_term(m, n, l);
                if (w != 0) value += w * w_term(m, n, l);
                at(l, m, n) = value;
            }
    }

    std::array<std::size_t, std::size_t(L)> offsets_{};
    std::vector<double> m_;
};

}  // namespace bounce::sh
