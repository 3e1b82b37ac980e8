#pragma once
/// \file embree/record_sampler.hpp
/// Irradiance records by ray tracing: a stratified hemisphere of rays through Embree, hits
/// shaded with direct light and shadow rays (the reference integrator's radiance), then
/// irradiance, gradients and radius from bounce/cache/gradients.hpp.
///
/// It models bounce::record_sampler (cache/record_sampler.hpp), as the GL single-plane rasterizer
/// does, so a cache takes either; one record alone is
///   std::optional<irradiance_record> operator()(glm::vec3 p, glm::vec3 n, double pixel_footprint).
///
/// With adaptive rays (bounce/cache/adaptive_hemisphere.hpp) a record starts from a grid of about
/// min_rays strata and adds rays to the strata next to uncertain ones until the estimated
/// relative standard error of its irradiance is below the target or max_rays are cast. With
/// ray_allocation::radiance (importance-sampled records) every record casts max_rays: min_rays
/// on that grid first, the rest to the strata whose neighbours' first rays saw the most light
/// (adaptive_hemisphere::allocate_by_radiance), reached by doublings of the strata; the
/// estimator (each stratum by its measure), gradients and variance are the adaptive ones.
/// rays_cast() counts the rays and records of every call, adaptive or not. Each record
/// carries the variance of its irradiance's luminance from its own rays (collapsed strata,
/// cache/record_filter.hpp), for the cache's neighbour filter.
///
/// What a record costs beyond its rays is kept small: the grid's trigonometry
/// (hemisphere_strata) is computed once per grid size, the per-record buffers are reused from
/// one record to the next on each thread (so measuring a record allocates nothing once they
/// have grown), and the adaptive rounds' rays go through the integrator's batched queries.

#include <bounce/cache/adaptive_hemisphere.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/cache/gradients.hpp>
#include <bounce/cache/record.hpp>
#include <bounce/cache/record_filter.hpp>
#include <bounce/luminance.hpp>
#include <bounce/cache/record_sampler.hpp>
#include <bounce/sampling.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

#include <tbb/parallel_for.h>

namespace bounce::embree {

class record_sampler {
public:
    /// The grid of a record when the caller names none: settings().hemisphere_samples of the
    /// integrator (default 1024) on the M x N grid of hemisphere_grid_for, M = round(sqrt(S /
    /// pi)) rings of equal projected solid angle by N = round(S / M) wedges (18 x 57 for
    /// 1024). That is the stratification cache/gradients.hpp differentiates, in the proportion
    /// N ~ pi M of Ward and Heckbert (1992) that Gautron and Krivanek's irradiance caching
    /// keeps (strata of about square solid angle); the rays per record are the one number a
    /// caller tunes, in the integrator's settings (records take 64 to 1024, references 1024).
    static hemisphere_grid default_grid(const reference_integrator& integrator) {
        return hemisphere_grid_for(integrator.settings().hemisphere_samples);
    }

    /// Records on default_grid(integrator); `limits`, `kind` and `seed` as below.
    explicit record_sampler(const reference_integrator& integrator, radius_limits limits = {},
                            translation_gradient_kind kind = translation_gradient_kind::krivanek_2005,
                            std::uint64_t seed = 7)
        : record_sampler(integrator, default_grid(integrator), limits, kind, seed) {}

    /// `grid`: the M x N strata per record (typical 16 x 50); `limits`: radius clamps;
    /// `kind`: translation-gradient formula; `seed`: base of the per-record streams (each keyed by its point).
    record_sampler(const reference_integrator& integrator, hemisphere_grid grid, radius_limits limits,
                   translation_gradient_kind kind = translation_gradient_kind::krivanek_2005, std::uint64_t seed = 7)
        : integrator_(integrator), grid_(checked(grid)), limits_(limits), kind_(kind), seed_(seed),
          strata_(std::make_shared<const hemisphere_strata>(grid_.m, grid_.n)) {}

    /// Adaptive rays per record when `adaptive.enabled`: a first round on
    /// adaptive_grid(min_rays), then up to max_rays (see the file comment); otherwise the
    /// fixed grid hemisphere_grid_for(adaptive.max_rays), as the constructor above.
    /// Throws parameter_error on bad settings (adaptive_rays::validate).
    record_sampler(const reference_integrator& integrator, adaptive_rays adaptive, radius_limits limits,
                   translation_gradient_kind kind = translation_gradient_kind::krivanek_2005, std::uint64_t seed = 7)
        : integrator_(integrator), grid_(grid_for(adaptive)), limits_(limits), kind_(kind), seed_(seed),
          adaptive_(adaptive), strata_(std::make_shared<const hemisphere_strata>(grid_.m, grid_.n)) {}

    /// What a record cost: every call since construction or reset_rays_cast(), adaptive or
    /// not, including those that returned nullopt.
    struct ray_tally {
        std::uint64_t records = 0;  ///< hemispheres measured
        std::uint64_t rays = 0;     ///< hemisphere rays cast for them (not counting shadow rays)
        std::uint32_t fewest = 0;   ///< fewest rays of one record (0 when none)
        std::uint32_t most = 0;     ///< most rays of one record
        double mean() const noexcept { return records ? double(rays) / double(records) : 0.0; }
    };
    ray_tally rays_cast() const noexcept {
        ray_tally t;
        t.records = tally_.records.load();
        t.rays = tally_.rays.load();
        t.most = tally_.most.load();
        t.fewest = t.records ? tally_.fewest.load() : 0u;
        return t;
    }
    /// Restarts rays_cast() from zero. Not while records are being measured.
    void reset_rays_cast() const noexcept { tally_.reset(); }

    /// The adaptive settings in use (enabled = false for a fixed grid).
    const adaptive_rays& adaptive() const noexcept { return adaptive_; }

    /// A record at (p, n); nullopt when the hemisphere yields no finite estimate.
    /// The rays are seeded by the bits of (p, n), so a record is a pure function of its
    /// point: the same whenever, and on whichever thread, it is asked for. That is what
    /// lets cpu::scan_cache_misses_batched measure records ahead of the scan. Thread-safe.
    std::optional<irradiance_record> operator()(glm::vec3 p, glm::vec3 n, double pixel_footprint) const {
        return measure(p, n, pixel_footprint, nullptr);
    }

    /// As operator(), and `*rays` (when not null) receives the hemisphere rays the record cast.
    std::optional<irradiance_record> measure(glm::vec3 p, glm::vec3 n, double pixel_footprint,
                                             std::uint32_t* rays) const {
        const scratch_lease lease;  // this thread's buffers (another set if nested work re-enters)
        scratch& w = lease.get();
        embree::hemisphere_samples& samples = w.world;
        const std::uint64_t key = point_key(p, n);
        integrator_.sample_hemisphere(p, n, grid_, derive_seed(seed_, 0x1c, key), samples);
        if (adaptive_.enabled) {
            const auto [est, cast, variance] = adaptive_estimate(samples, key, w);
            tally_.add(cast);
            if (rays) *rays = cast;
            return finish(p, samples, est, variance, pixel_footprint);
        }
        tally_.add(grid_.count());
        if (rays) *rays = grid_.count();
        bounce::hemisphere_samples& local = w.local;
        local.rings = grid_.m;
        local.wedges = grid_.n;
        const std::size_t count = samples.direction.size();
        local.direction.resize(count);
        for (std::size_t i = 0; i < count; ++i) {
            const glm::vec3 d = samples.direction[i];
            local.direction[i] = {glm::dot(d, samples.tangent), glm::dot(d, samples.bitangent), glm::dot(d, samples.normal)};
        }
        // Swapped, not copied: both sides keep a buffer of the grid's size for the next record.
        local.radiance.swap(samples.radiance);
        local.distance.swap(samples.distance);
        // Distances are measured from p + eps n and can be 0 where another surface touches
        // p (a corner); no surface is nearer than the offset itself, so floor them there.
        const float eps = integrator_.ray_epsilon();
        for (float& d : local.distance) d = std::max(d, eps);
        return finish(p, samples, estimate_hemisphere(local, *strata_, kind_, needs_hessian()),
                      stratified_luminance_variance(local.radiance, grid_.m, grid_.n), pixel_footprint);
    }

    /// Records for points[k], normals[k], footprints[k] into out[k], the points on every
    /// core (each record is a pure function of its point, so the order does not matter).
    /// Throws parameter_error when the spans' sizes differ.
    void operator()(std::span<const glm::vec3> points, std::span<const glm::vec3> normals,
                    std::span<const double> footprints, std::span<std::optional<irradiance_record>> out) const {
        require(normals.size() == points.size() && footprints.size() == points.size() && out.size() == points.size(),
                "points", "points, normals, footprints and out must have one entry per record");
        tbb::parallel_for(std::size_t(0), points.size(),
                          [&](std::size_t k) { out[k] = (*this)(points[k], normals[k], footprints[k]); });
    }

    /// The hemisphere rays the records at points[k], normals[k] would cast, traced without
    /// shading, the points on every core; returns the rays cast. For comparing a record's
    /// cost with Embree's raw rate on the same rays. With adaptive rays: the first round's
    /// rays only (the later rounds' depend on the shading).
    std::size_t trace_only(std::span<const glm::vec3> points, std::span<const glm::vec3> normals) const {
        require(normals.size() == points.size(), "normals", "must have one entry per point");
        tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t k) {
            integrator_.trace_hemisphere(points[k], normals[k], grid_, derive_seed(seed_, 0x1c, point_key(points[k], normals[k])));
        });
        return points.size() * grid_.count();
    }

    /// Mean luminance of the irradiance at points[k], normals[k] from this sampler's first
    /// round alone (the fixed grid when adaptive rays are off), the points on every core, not
    /// counted in rays_cast(). For an adaptive_rays::irradiance_floor on the scene's scale:
    /// a few hundred points of the frame's G-buffer suffice. 0 for no points.
    double mean_irradiance(std::span<const glm::vec3> points, std::span<const glm::vec3> normals) const {
        require(normals.size() == points.size(), "normals", "must have one entry per point");
        std::vector<double> e(points.size());
        tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t k) {
            embree::hemisphere_samples samples;
            integrator_.sample_hemisphere(points[k], normals[k], grid_, derive_seed(seed_, 0x1e, point_key(points[k], normals[k])),
                                          samples);
            e[k] = rec709_luminance<double, glm::dvec3>(glm::dvec3(samples.irradiance()));
        });
        double sum = 0;
        for (const double x : e) sum += x;
        return points.empty() ? 0.0 : sum / double(points.size());
    }

    hemisphere_grid grid() const noexcept { return grid_; }

private:
    const reference_integrator& integrator_;
    hemisphere_grid grid_;
    radius_limits limits_;
    translation_gradient_kind kind_;
    std::uint64_t seed_;
    adaptive_rays adaptive_{};
    std::shared_ptr<const hemisphere_strata> strata_;  // of grid_ (shared by copies)

    // One record's buffers, kept per thread between records: the hemisphere as traced and in
    // the local frame, the adaptive rounds' rays and results, and the strata of the adaptive
    // fine grids met so far (a few sizes; the most recent first).
    struct scratch {
        embree::hemisphere_samples world;
        bounce::hemisphere_samples local;
        std::vector<std::size_t> cell_of;
        std::vector<glm::vec2> jitter;
        std::vector<glm::vec3> directions, radiance;
        std::vector<float> distance;
        std::vector<ray> rays;
        std::vector<std::uint64_t> seeds;
        std::vector<std::shared_ptr<const hemisphere_strata>> fine_strata;
        std::optional<adaptive_hemisphere> hemisphere;  // the adaptive record's strata
        bounce::hemisphere_samples fine;                // and its fine grid

        const hemisphere_strata& strata_for(std::uint32_t rings, std::uint32_t wedges) {
            for (std::size_t i = 0; i < fine_strata.size(); ++i)
                if (fine_strata[i]->rings == rings && fine_strata[i]->wedges == wedges) {
                    std::rotate(fine_strata.begin(), fine_strata.begin() + std::ptrdiff_t(i),
                                fine_strata.begin() + std::ptrdiff_t(i) + 1);
                    return *fine_strata.front();
                }
            if (fine_strata.size() == 8) fine_strata.pop_back();
            fine_strata.insert(fine_strata.begin(), std::make_shared<const hemisphere_strata>(rings, wedges));
            return *fine_strata.front();
        }
    };
    // The calling thread's scratch while a record is measured. A record's own work spawns no
    // parallel work, but should a caller's nested TBB work re-enter measure() on this thread,
    // the inner call takes the next set, so no two records share one.
    class scratch_lease {
    public:
        scratch_lease() : depth_(depth()++) {
            auto& sets = pool();
            while (sets.size() <= depth_) sets.push_back(std::make_unique<scratch>());
            set_ = sets[depth_].get();
        }
        ~scratch_lease() { --depth(); }
        scratch_lease(const scratch_lease&) = delete;
        scratch_lease& operator=(const scratch_lease&) = delete;
        scratch& get() const noexcept { return *set_; }

    private:
        static std::size_t& depth() {
            thread_local std::size_t d = 0;
            return d;
        }
        static std::vector<std::unique_ptr<scratch>>& pool() {
            thread_local std::vector<std::unique_ptr<scratch>> sets;
            return sets;
        }
        std::size_t depth_;
        scratch* set_;
    };

    // Atomic totals (copies start from the original's counts).
    struct tally {
        std::atomic<std::uint64_t> records{0}, rays{0};
        std::atomic<std::uint32_t> fewest{~0u}, most{0};
        tally() = default;
        tally(const tally& o) : records(o.records.load()), rays(o.rays.load()), fewest(o.fewest.load()), most(o.most.load()) {}
        tally& operator=(const tally&) = delete;
        void add(std::uint32_t cast) noexcept {
            records.fetch_add(1);
            rays.fetch_add(cast);
            std::uint32_t f = fewest.load();
            while (cast < f && !fewest.compare_exchange_weak(f, cast)) {}
            std::uint32_t m = most.load();
            while (cast > m && !most.compare_exchange_weak(m, cast)) {}
        }
        void reset() noexcept {
            records = 0;
            rays = 0;
            fewest = ~0u;
            most = 0;
        }
    };
    mutable tally tally_;

    // Only the Hessian radius and the mean-distance floor read the estimate's Hessian and mean distance.
    bool needs_hessian() const noexcept {
        return limits_.policy == radius_policy::hessian || limits_.min_mean_distance > 0.f;
    }

    static hemisphere_grid checked(hemisphere_grid grid) {
        require(grid.m > 0 && grid.n > 0, "grid", "need at least one stratum in each direction");
        return grid;
    }

    static hemisphere_grid grid_for(const adaptive_rays& a) {
        a.validate();
        if (!a.enabled) return hemisphere_grid_for(a.max_rays);
        const adaptive_grid_size g = adaptive_grid(a.min_rays);
        return {g.rings, g.wedges};
    }

    // `variance`: of E's luminance, from the record's own rays (NaN: unknown, stored as 0).
    std::optional<irradiance_record> finish(glm::vec3 p, const embree::hemisphere_samples& samples,
                                     const hemisphere_estimate& est, double variance, double pixel_footprint) const {
        irradiance_record rec = make_record(p, samples.normal, samples.tangent, samples.bitangent, est, limits_,
                                            pixel_footprint);
        rec.variance = std::isfinite(variance) ? float(variance) : 0.f;
        if (!std::isfinite(rec.radius) || !(rec.radius > 0.f)) return std::nullopt;
        return rec;
    }

    // The first round (the fixed grid's samples) and as many later rounds as the target
    // needs: each round asks adaptive_hemisphere::plan for at most as many rays as were
    // cast so far (at least an eighth of them), splits the chosen cells' sub-strata with
    // jitters from a stream keyed by the point and the round, and shades the new rays as
    // sample_hemisphere does, in one batched query (bitwise the single-ray incoming_radiance).
    // Returns the estimate, the rays cast and the variance of E's luminance (collapsed strata).
    std::tuple<hemisphere_estimate, std::uint32_t, double> adaptive_estimate(const embree::hemisphere_samples& samples,
                                                                             std::uint64_t key, scratch& w) const {
        if (!w.hemisphere) w.hemisphere.emplace(grid_.m, grid_.n);
        adaptive_hemisphere& h = *w.hemisphere;
        h.reset(grid_.m, grid_.n);
        const float eps = integrator_.ray_epsilon();
        auto local_of = [&](const glm::vec3& d) {
            return glm::vec3(glm::dot(d, samples.tangent), glm::dot(d, samples.bitangent), glm::dot(d, samples.normal));
        };
        for (std::size_t i = 0; i < samples.direction.size(); ++i) {
            const glm::vec3 l = local_of(samples.direction[i]);
            h.add(i, h.jitter_of(i, l), l, samples.radiance[i], std::max(samples.distance[i], eps));
        }
        const std::uint64_t cap = std::max<std::uint64_t>(adaptive_.max_rays, grid_.count());
        std::uint64_t used = grid_.count();
        std::vector<std::size_t>& cell_of = w.cell_of;
        std::vector<glm::vec2>& jitter = w.jitter;
        std::vector<glm::vec3>& local = w.directions;
        std::vector<glm::vec3>& radiance = w.radiance;
        std::vector<float>& distance = w.distance;
        // One round: doubles every cell with extra[c] > 0 (the jitters from a stream keyed by
        // the point and the round), shaded in one batched query.
        auto cast_round = [&](const std::vector<std::uint32_t>& extra, std::uint64_t round) {
            const std::uint64_t stream = derive_seed(seed_, 0x1d, key ^ (round * 0x9e3779b97f4a7c15ULL));
            pcg32 rng(stream);
            cell_of.clear();
            jitter.clear();
            local.clear();
            for (std::size_t c = 0; c < extra.size(); ++c) {
                if (extra[c] == 0) continue;
                for (const glm::vec2 u : h.refinement_jitters(c, [&] { return rng.next_float(); })) {
                    cell_of.push_back(c);
                    jitter.push_back(u);
                    local.push_back(h.direction_in(c, u));
                }
            }
            const std::size_t count = local.size();
            radiance.resize(count);
            distance.resize(count);
            w.rays.resize(count);
            w.seeds.resize(count);
            const glm::vec3 origin = samples.origin + eps * samples.normal;
            for (std::size_t i = 0; i < count; ++i) {
                ray& r = w.rays[i];
                r = ray{};
                r.origin = origin;
                const glm::vec3 l = local[i];
                r.direction = glm::normalize(l.x * samples.tangent + l.y * samples.bitangent + l.z * samples.normal);
                w.seeds[i] = derive_seed(stream, 0x2e, i);
            }
            integrator_.incoming_radiance(w.rays, w.seeds, radiance, distance);
            for (std::size_t i = 0; i < count; ++i)
                h.add(cell_of[i], jitter[i], local[i], radiance[i], std::max(distance[i], eps));
            used += count;
        };
        if (adaptive_.allocation != ray_allocation::variance) {
            // Importance: every count decided from the first round, then reached by doublings.
            const std::vector<std::uint32_t> target =
                h.allocate_by_radiance(cap - used, adaptive_.defensive, adaptive_.allocation == ray_allocation::contrast);
            std::vector<std::uint32_t> extra(target.size());
            for (std::uint64_t round = 1;; ++round) {
                bool any = false;
                for (std::size_t c = 0; c < target.size(); ++c) {
                    extra[c] = h.count(c) < target[c] ? h.count(c) : 0u;
                    any |= extra[c] > 0;
                }
                if (!any) break;
                cast_round(extra, round);
            }
        } else {
            for (std::uint64_t round = 1; used < cap && round <= 16; ++round) {
                const double scale = std::max(h.luminance_irradiance(), adaptive_.irradiance_floor);
                const double allowed = adaptive_.target * scale;
                const double v = h.variance();
                if (!(v > allowed * allowed)) break;
                const std::uint64_t budget = std::min(cap - used, used);
                const std::vector<std::uint32_t> extra = h.plan(budget, allowed * allowed, std::min(budget, used / 8));
                if (extra.empty()) break;
                cast_round(extra, round);
            }
        }
        if (adaptive_.cell_gradients && adaptive_.allocation != ray_allocation::variance && !needs_hessian()) {
            // Gradients on the first-round grid of cell means; R from every sample's distance.
            h.cell_samples(w.fine);
            hemisphere_estimate est = estimate_hemisphere(w.fine, *strata_, kind_, false);
            const double inverse = h.mean_inverse_distance();
            est.harmonic_mean_distance = inverse > 0 ? 1.0 / inverse : std::numeric_limits<double>::infinity();
            return {est, std::uint32_t(used), h.variance()};
        }
        // Directions matter to the Hessian and Ward and Heckbert's walls only.
        bounce::hemisphere_samples& fine = w.fine;
        h.fine_samples(fine, needs_hessian() || kind_ != translation_gradient_kind::krivanek_2005);
        return {estimate_hemisphere(fine, w.strata_for(fine.rings, fine.wedges), kind_, needs_hessian()), std::uint32_t(used),
                h.variance()};
    }

    // Distinct points get independent streams, the same point the same stream.
    static std::uint64_t point_key(const glm::vec3& p, const glm::vec3& n) noexcept {
        return hash_floats({p.x, p.y, p.z, n.x, n.y, n.z});
    }
};

static_assert(bounce::record_sampler<const embree::record_sampler>);

}  // namespace bounce::embree
