#pragma once
/// \file octree_cache.hpp
/// The classical irradiance cache (Ward et al. 1988; the octree of pbrt-v2): records
/// stored in an octree by their zone of influence, looked up per pixel. It is the baseline
/// irradiance splatting must beat; it uses the same records, weights and a.
///
/// A record is stored in every node that overlaps its zone's bounding box, at the first
/// depth whose node diagonal is smaller than the zone's (pbrt-v2's rule); a lookup walks
/// from the root to the leaf containing p and tests the records met on the way. The tree
/// depends on a (zones are a * R): changing a means rebuilding it, which splatting avoids.
///
/// Lookups evaluate the records they meet one at a time (the classical code, and the
/// baseline the irradiance-splatting issue names) or four at a time on cpu::lanes, the
/// splat's own instantiation of the kernel (`octree_evaluation::lanes`): the two give the
/// same sums, bit for bit, so the lane form measures what vectorization alone buys.

#include <bounce/camera.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/cache/record.hpp>
#include <bounce/cache/weighting.hpp>
#include <bounce/cpu/lanes.hpp>
#include <bounce/cpu/splatting.hpp>

#include <array>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/parallel_for.h>

namespace bounce::cpu {

/// How an octree lookup evaluates the records it meets: one at a time, or the records whose
/// zone holds the point four at a time (same sums, bit for bit).
enum class octree_evaluation { scalar, lanes };

template <class Weight>
class octree_cache {
public:
    /// An empty cache over the box [lo, hi] (the scene bounds; records outside are clamped
    /// into the root), for accuracy `sp.a`.
    octree_cache(glm::vec3 lo, glm::vec3 hi, const splat_params& sp, int max_depth = 16)
        : lo_(lo), hi_(hi), sp_(sp), max_depth_(max_depth), root_(std::make_unique<node>()) {
        sp.validate();
        require(hi.x >= lo.x && hi.y >= lo.y && hi.z >= lo.z, "bounds", "hi must not be below lo");
        // A cube, slightly enlarged, so every record's centre falls inside.
        const glm::vec3 c = 0.5f * (lo + hi);
        const float half = 0.5f * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 1e-6f}) * 1.001f;
        lo_ = c - half;
        hi_ = c + half;
    }

    const std::vector<irradiance_record>& records() const noexcept { return records_; }
    const splat_params& params() const noexcept { return sp_; }

    /// Adds a record (copied) to the tree.
    void insert(const irradiance_record& rec) {
        records_.push_back(rec);
        const auto idx = std::uint32_t(records_.size() - 1);
        const float zone = Weight::template influence_radius<float>(rec.radius, sp_.a);
        insert(*root_, lo_, hi_, rec.position - zone, rec.position + zone, 2.f * zone * std::sqrt(3.f), idx, 0);
    }

    /// (sum of w * rho/pi * E_k(p), sum of w) over the records reaching p: the value a
    /// splat buffer holds at that pixel, up to the order of the float additions (records
    /// are met root to leaf here, in index order there).
    glm::vec4 lookup(const glm::vec3& p, const glm::vec3& n, const glm::vec3& albedo) const {
        glm::vec4 sum(0.f);
        walk(p, [&](const irradiance_record& r) {
            sum += detail::contribution<Weight>(r, p, n, albedo, sp_, detail::culling_radius2<Weight>(r, sp_.a));
        });
        return sum;
    }

    /// `lookup` with the kernel on four records at a time: the walk keeps the records whose
    /// zone holds p (the scalar code's distance test) in the order it meets them, and they
    /// are evaluated in groups of four, their non-zero terms added in that order: the same
    /// float additions as `lookup`.
    glm::vec4 lookup_lanes(const glm::vec3& p, const glm::vec3& n, const glm::vec3& albedo) const {
        std::array<const irradiance_record*, 64> near;
        std::size_t count = 0;
        glm::vec4 sum(0.f);
        const auto flush = [&] {
            with_kernel_flags(sp_, [&](auto gradients, auto front_test) {
                add_lanes<decltype(gradients)::value, decltype(front_test)::value>(std::span(near).first(count), p, n,
                                                                                   albedo, sum);
            });
            count = 0;
        };
        walk(p, [&](const irradiance_record& r) {
            const glm::vec3 d = p - r.position;
            if (!(glm::dot(d, d) <= detail::culling_radius2<Weight>(r, sp_.a))) return;
            near[count++] = &r;
            if (count == near.size()) flush();
        });
        if (count) flush();
        return sum;
    }

    /// Classical first pass: visit pixels in row order; where the cache's weight is below
    /// `min_weight`, create a record and insert it. Later pixels see it; earlier ones do
    /// not, which is why the classical method needs the second pass (`render`).
    template <class Create>
    std::size_t fill(const gbuffer_view<float>& gb, float min_weight, Create&& create) {
        std::size_t created = 0;
        for (std::size_t y = 0; y < gb.height(); ++y)
            for (std::size_t x = 0; x < gb.width(); ++x) {
                if (!gb.covered(x, y)) continue;
                if (lookup(gb.position(x, y), gb.normal(x, y), gb.albedo(x, y)).w >= min_weight) continue;
                if (auto rec = create(x, y)) {
                    insert(*rec);
                    ++created;
                }
            }
        return created;
    }

    /// Second pass: the (sum, weight) of every pixel by lookups, in parallel.
    void render(const gbuffer_view<float>& gb, image_view<glm::vec4> out,
                octree_evaluation evaluation = octree_evaluation::scalar) const {
        require(out.width() == gb.width() && out.height() == gb.height(), "out", "size differs from the G-buffer");
        const bool lanes = evaluation == octree_evaluation::lanes;
        tbb::parallel_for(std::size_t(0), gb.height(), [&](std::size_t y) {
            for (std::size_t x = 0; x < gb.width(); ++x) {
                if (!gb.covered(x, y)) {
                    out(x, y) = glm::vec4(0.f);
                    continue;
                }
                const glm::vec3 p = gb.position(x, y), n = gb.normal(x, y), albedo = gb.albedo(x, y);
                out(x, y) = lanes ? lookup_lanes(p, n, albedo) : lookup(p, n, albedo);
            }
        });
    }

private:
    // Calls f(record) for the records stored on the path from the root to the leaf that
    // contains p, root first, each node's in insertion order.
    template <class F>
    void walk(const glm::vec3& p, F&& f) const {
        const node* nd = root_.get();
        glm::vec3 lo = lo_, hi = hi_;
        while (nd) {
            for (std::uint32_t i : nd->items) f(records_[i]);
            const glm::vec3 mid = 0.5f * (lo + hi);
            const int child = (p.x > mid.x) | ((p.y > mid.y) << 1) | ((p.z > mid.z) << 2);
            if (!nd->children[child]) break;
            child_box(lo, hi, child, lo, hi);
            nd = nd->children[child].get();
        }
    }

    // Adds the contributions of records `recs` at one point, four records per kernel call;
    // a short last group repeats its last record in the spare lanes and ignores them.
    template <bool Gradients, bool FrontTest>
    void add_lanes(std::span<const irradiance_record* const> recs, const glm::vec3& p, const glm::vec3& n,
                   const glm::vec3& albedo, glm::vec4& sum) const {
        using namespace lanes;
        const vec3x4 pv = vec3x4::broadcast(p), nv = vec3x4::broadcast(n), av = vec3x4::broadcast(albedo);
        const f32x4 a(sp_.a), max_extrapolation(sp_.max_extrapolation), front_tolerance(sp_.front_tolerance);
        for (std::size_t g = 0; g < recs.size(); g += 4) {
            const std::size_t valid = std::min<std::size_t>(4, recs.size() - g);
            const irradiance_record* r[4];
            for (std::size_t i = 0; i < 4; ++i) r[i] = recs[g + std::min(i, valid - 1)];
            const auto field = [&](auto member) {
                return vec3x4::gather(r[0]->*member, r[1]->*member, r[2]->*member, r[3]->*member);
            };
            const auto gradient = [&](auto member, int c) {
                return vec3x4::gather((r[0]->*member)[c], (r[1]->*member)[c], (r[2]->*member)[c], (r[3]->*member)[c]);
            };
            const f32x4 inv_r(1.f / r[0]->radius, 1.f / r[1]->radius, 1.f / r[2]->radius, 1.f / r[3]->radius);
            const auto c = splat_contribution<Weight, Gradients, FrontTest, f32x4, vec3x4>(
                pv, nv, av, field(&irradiance_record::position), field(&irradiance_record::normal), inv_r, a,
                field(&irradiance_record::irradiance), gradient(&irradiance_record::rotation, 0),
                gradient(&irradiance_record::rotation, 1), gradient(&irradiance_record::rotation, 2),
                gradient(&irradiance_record::translation, 0), gradient(&irradiance_record::translation, 1),
                gradient(&irradiance_record::translation, 2), max_extrapolation, front_tolerance);
            for (std::size_t i = 0; i < valid; ++i)
                if (c[3][int(i)] > 0.f) sum += glm::vec4(c[0][int(i)], c[1][int(i)], c[2][int(i)], c[3][int(i)]);
        }
    }

    struct node {
        std::vector<std::uint32_t> items;
        std::array<std::unique_ptr<node>, 8> children;
    };

    static void child_box(glm::vec3 lo, glm::vec3 hi, int child, glm::vec3& clo, glm::vec3& chi) {
        const glm::vec3 mid = 0.5f * (lo + hi);
        clo = {child & 1 ? mid.x : lo.x, child & 2 ? mid.y : lo.y, child & 4 ? mid.z : lo.z};
        chi = {child & 1 ? hi.x : mid.x, child & 2 ? hi.y : mid.y, child & 4 ? hi.z : mid.z};
    }

    void insert(node& nd, glm::vec3 lo, glm::vec3 hi, glm::vec3 blo, glm::vec3 bhi, float diag, std::uint32_t idx, int depth) {
        // Store here once the node is no larger than the zone (or at the depth limit).
        if (depth == max_depth_ || glm::length(hi - lo) < diag) {
            nd.items.push_back(idx);
            return;
        }
        for (int c = 0; c < 8; ++c) {
            glm::vec3 clo, chi;
            child_box(lo, hi, c, clo, chi);
            if (bhi.x < clo.x || blo.x > chi.x || bhi.y < clo.y || blo.y > chi.y || bhi.z < clo.z || blo.z > chi.z)
                continue;
            if (!nd.children[c]) nd.children[c] = std::make_unique<node>();
            insert(*nd.children[c], clo, chi, blo, bhi, diag, idx, depth + 1);
        }
    }

    glm::vec3 lo_, hi_;
    splat_params sp_;
    int max_depth_;
    std::unique_ptr<node> root_;
    std::vector<irradiance_record> records_;
};

}  // namespace bounce::cpu
